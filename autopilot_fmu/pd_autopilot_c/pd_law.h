/* The PD autopilot's law, eq (20) of Tomera (2010), for both of this FMU's entry points:
   pd_autopilot_c.c (FMI 2.0) and pd_autopilot_c_fmi3.c (FMI 3.0) include it.

       delta_c = Kp wrap(psi - psi_d) + Kd r,   wrap: to (-pi, pi]

   The same law as autopilot_fmu/pd.py, operation for operation on IEEE doubles (wrap as
   fmukit.numerics.wrap), so that it gives the same bits. */
#ifndef PD_LAW_H
#define PD_LAW_H

#include <math.h>

static const double PD_PI = 3.141592653589793;     /* the double nearest pi, as math.pi */

/* The angle mod 2 pi in (-pi, pi]: the short way round. */
static double pd_wrap(double angle) {
    double wrapped = remainder(angle, 2.0 * PD_PI);
    return wrapped == -PD_PI ? PD_PI : wrapped;
}

/* eq (20): the commanded rudder angle, rad, for the heading psi and desired course psi_d
   (rad), the yaw rate r (rad/s) and the gains Kp (rad of rudder per rad) and Kd (s). */
static double pd_rudder_command(double Kp, double Kd, double psi, double r, double psi_d) {
    return Kp * pd_wrap(psi - psi_d) + Kd * r;
}

#endif
