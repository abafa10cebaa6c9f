"""The ship's instruments as a co-simulation FMU (fmus/sensors.fmu), between the ship and the
controllers: gyro heading and rate of turn with bias, noise and quantisation, GNSS position
with noise (ship_fmu.sensors); each reading direct feedthrough from the true value."""
from fmukit.slave import ModelSlave, Var
from ship_fmu.sensors import Sensors

_S = Sensors()


class SensorsSlave(ModelSlave):
    model_name = "sensors"
    description = ("Gyrocompass and rate gyro (bias, white noise, quantisation) and GNSS "
                   "position (white noise), each step's noise seeded")
    variables = (
        Var.input("psi", 0.0, "rad", "true heading"),
        Var.input("r", 0.0, "rad/s", "true yaw rate", -100.0, 100.0),
        Var.input("x", 0.0, "m", "true north position"),
        Var.input("y", 0.0, "m", "true east position"),
        Var.output("psi_m", "rad", "measured heading", depends=("psi", "psi_bias", "psi_noise",
                   "psi_resolution"), get=lambda s: s.model.heading(s.psi)),
        Var.output("r_m", "rad/s", "measured yaw rate", depends=("r", "r_bias", "r_noise",
                   "r_resolution"), get=lambda s: s.model.rate(s.r)),
        Var.output("x_m", "m", "measured north position", depends=("x", "position_noise"),
                   get=lambda s: s.model.position(s.x, s.y)[0]),
        Var.output("y_m", "m", "measured east position", depends=("y", "position_noise"),
                   get=lambda s: s.model.position(s.x, s.y)[1]),
        Var.parameter("psi_bias", _S.psi_bias, "rad", "gyrocompass bias", -1.0, 1.0),
        Var.parameter("psi_noise", _S.psi_noise, "rad", "gyrocompass noise, standard "
                      "deviation", 0.0, 1.0),
        Var.parameter("psi_resolution", _S.psi_resolution, "rad", "gyrocompass reading's "
                      "step; 0: none", 0.0, 1.0),
        Var.parameter("r_bias", _S.r_bias, "rad/s", "rate gyro bias", -1.0, 1.0),
        Var.parameter("r_noise", _S.r_noise, "rad/s", "rate gyro noise, standard deviation",
                      0.0, 1.0),
        Var.parameter("r_resolution", _S.r_resolution, "rad/s", "rate gyro reading's step; "
                      "0: none", 0.0, 1.0),
        Var.parameter("position_noise", _S.position_noise, "m", "GNSS noise, standard "
                      "deviation north and east (1 m at full scale is 0.014 m)", 0.0, 100.0),
        Var.parameter("sensor_seed", _S.seed, description="seed of the noise", min=0,
                      max=2**31 - 1),
    )

    def build_model(self) -> Sensors:
        return Sensors(self.psi_bias, self.psi_noise, self.psi_resolution, self.r_bias,
                       self.r_noise, self.r_resolution, self.position_noise, self.sensor_seed)

    def step_model(self, t: float, h: float) -> None:
        self.model.step()
