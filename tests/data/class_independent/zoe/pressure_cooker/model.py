"""The cooker as plain Python: the nodes only move numbers in and out of it."""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class Cooker:
    """Pressure in kPa above ambient; heating adds, an open valve vents."""

    heat_kpa_per_s: float
    vent_kpa_per_s: float
    pressure: float = 0.0
    history: list[float] = field(default_factory=list)

    def step(self, dt: float, valve_open: float) -> float:
        self.pressure += (self.heat_kpa_per_s - valve_open * self.vent_kpa_per_s) * dt
        self.pressure = max(0.0, self.pressure)
        self.history = [*self.history[-9:], self.pressure]
        return self.pressure
