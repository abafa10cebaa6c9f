"""The rudder program of a turning circle or a zig-zag test (IMO MSC.137(76))."""

class RudderProgram:
    """Executes ``delta`` at t = 0 (positive: to port, headings go negative first) and
    reverses it each time the heading deviation passes -+psi_switch; 0 holds it."""

    def __init__(self, delta: float, psi_switch: float):    # the FMU checks both: >= 0
        self.delta, self.psi_switch = delta, psi_switch
        self.sign, self.reversals = 1, 0

    def _next(self, psi: float) -> tuple[int, int]:
        if self.psi_switch > 0.0 and self.sign * psi <= -self.psi_switch:
            return -self.sign, self.reversals + 1
        return self.sign, self.reversals

    def command(self, psi: float) -> float:
        return self._next(psi)[0] * self.delta

    def reversals_at(self, psi: float) -> int:
        return self._next(psi)[1]

    def update(self, psi: float) -> None:
        self.sign, self.reversals = self._next(psi)

    def snapshot(self) -> dict[str, int]:
        return {"sign": self.sign, "reversals": self.reversals}

    def restore(self, snapshot: dict[str, int]) -> None:
        self.sign, self.reversals = int(snapshot["sign"]), int(snapshot["reversals"])
