"""Every physical parameter of the joint, in SI units, with its source.

Sections (§) refer to ``shared/SPEC.md``; equation numbers are the thesis's.
Conversions to mm, degrees, grams and kPa happen only in ``twin/units.py``
callers at the user-facing edge.
"""

from __future__ import annotations

import dataclasses
import math

from twin.exceptions import InvalidParameter


def _require_positive(owner: object, *names: str) -> None:
    for name in names:
        value = getattr(owner, name)
        if not (value > 0 and math.isfinite(value)):
            raise InvalidParameter(f"{type(owner).__name__}.{name} must be positive and finite, got {value!r}")


@dataclasses.dataclass(frozen=True)
class CylinderParams:
    """Single-acting water cylinders, push-push on the two racks (§2)."""

    bore_diameter: float = 4e-3  # m
    max_stroke: float = 20e-3  # m
    rated_pressure: float = 700e3  # Pa (gauge)

    def __post_init__(self) -> None:
        _require_positive(self, "bore_diameter", "max_stroke", "rated_pressure")

    @property
    def bore_area(self) -> float:
        """A = pi (D/2)^2 = 1.2566e-5 m^2 (§2)."""
        return math.pi * (self.bore_diameter / 2.0) ** 2


@dataclasses.dataclass(frozen=True)
class GearParams:
    """Rack-pinion-spur train, 48 diametral pitch (§2, eq. 3.4.1)."""

    pinion_pitch_diameter: float = 3.71e-3  # m, 7 teeth
    spur_pitch_diameter: float = 9.525e-3  # m, 18 teeth
    pinion_teeth: int = 7
    spur_teeth: int = 18
    diametral_pitch: float = 48.0  # teeth per inch
    pinion_face_width: float = 0.125 * 0.0254  # m
    spur_face_width: float = 0.0625 * 0.0254  # m
    safe_bending_stress: float = 12_000 * 6894.757  # Pa, S = 12,000 psi, brass (eq. 3.5.4)
    pinion_form_factor: float = 0.176  # Y, Lewis (eq. 3.5.4)
    spur_form_factor: float = 0.270  # Y, Lewis (eq. 3.5.4)

    def __post_init__(self) -> None:
        _require_positive(self, "pinion_pitch_diameter", "spur_pitch_diameter", "diametral_pitch")

    @property
    def pinion_radius(self) -> float:
        return self.pinion_pitch_diameter / 2.0  # m

    @property
    def spur_radius(self) -> float:
        """r_s: theta = y / r_s (eq. 3.4.1, 12.03 deg/mm)."""
        return self.spur_pitch_diameter / 2.0  # m

    @property
    def diametral_pitch_si(self) -> float:
        """P_d in teeth per metre of pitch diameter."""
        return self.diametral_pitch / 0.0254  # 1/m

    @property
    def ratio(self) -> float:
        """Spur to pinion speed reduction, 2.57:1 (§2)."""
        return self.spur_pitch_diameter / self.pinion_pitch_diameter


@dataclasses.dataclass(frozen=True)
class MassParams:
    """Moving masses and inertias (§2, thesis appendix A)."""

    rack_mass: float = 0.46e-3  # kg, each rack
    piston_mass: float = 2.0e-3  # kg, cylinder shaft + piston, each
    water_mass: float = 27.16e-3  # kg, water in cylinders and tubing, both sides
    pinion_inertia: float = 4.8e-10  # kg m^2
    spur_inertia: float = 1.095e-8  # kg m^2
    link_mass: float = 0.6e-3  # kg
    link_length: float = 35e-3  # m, *inferred* from J = m l^2 / 3 = 2.45e-7 kg m^2
    thesis_total_mass: float = 32.9e-3  # kg, the thesis's lumped M (link via r = 35 mm)
    payload_density: float = 8500.0  # kg/m^3, brass; sizes the payload sphere (*inferred*)

    def __post_init__(self) -> None:
        _require_positive(self, "rack_mass", "piston_mass", "water_mass", "pinion_inertia",
                          "spur_inertia", "link_mass", "link_length", "thesis_total_mass", "payload_density")

    @property
    def rack_side_mass(self) -> float:
        """Linear mass moving with one rack: rack + piston + half the water."""
        return self.rack_mass + self.piston_mass + self.water_mass / 2.0  # kg

    @property
    def link_inertia(self) -> float:
        """J = m l^2 / 3 about the shaft (§2)."""
        return self.link_mass * self.link_length**2 / 3.0  # kg m^2


@dataclasses.dataclass(frozen=True)
class ValveParams:
    """On/off solenoid valves, pulse-width-modulated (§3) and eq. 4.4.2."""

    pwm_period: float = 16e-3  # s, 62.5 Hz
    switching_period: float = 1e-3  # s, the DAQ's output tick (§5, §6): duties realised in whole ticks; 0 = continuous
    opening_delay: float = 5e-3  # s
    closing_delay: float = 2e-3  # s
    dead_zone_duty: float = 30.0  # %, below it the real valve does not open
    resistance_coefficient: float = 1.8372e14  # Pa s/m^3 at d = 1 % (eq. 4.4.2, *resolution*: Pa s/m^3)
    resistance_exponent: float = -2.1706  # eq. 4.4.2

    def __post_init__(self) -> None:
        _require_positive(self, "pwm_period", "resistance_coefficient")
        if self.opening_delay < 0 or self.closing_delay < 0:
            raise InvalidParameter("valve delays must be non-negative")
        if self.switching_period < 0 or self.switching_period > self.pwm_period:
            raise InvalidParameter(f"switching_period must be in [0, pwm_period], got {self.switching_period}")
        if not 0.0 <= self.dead_zone_duty < 100.0:
            raise InvalidParameter(f"dead_zone_duty must be in [0, 100) %, got {self.dead_zone_duty}")

    def resistance(self, duty_percent):
        """R(d) = 1.8372e14 d^-2.1706 Pa s/m^3 (eq. 4.4.2); d in %, d > 0."""
        return self.resistance_coefficient * duty_percent ** self.resistance_exponent

    def duty_for_resistance(self, resistance):
        """Inverse of eq. 4.4.2: d = (R / 1.8372e14)^(1 / -2.1706) % (eq. 5.3.3)."""
        return (resistance / self.resistance_coefficient) ** (1.0 / self.resistance_exponent)

    @property
    def open_resistance(self) -> float:
        """R1: a valve fully on, R(100 %) = 8.36e9 Pa s/m^3 (§4)."""
        return float(self.resistance(100.0))


@dataclasses.dataclass(frozen=True)
class FrictionParams:
    """Force loss F_l = F_c(y) sgn(v) + F_v v (eqs. 4.5.5 and 4.5.7)."""

    viscous: float = 45.9  # N s/m, F_v (eq. 4.5.5)
    # eq. 4.5.7, y in metres, highest power first; F_c in N.
    coulomb_poly: tuple[float, ...] = (-3.051e14, 1.587e13, -3.244e11, 3.294e9, -1.727e7, 4.36e4, -39.551)
    fit_range: tuple[float, float] = (2e-3, 14.5e-3)  # m, where eq. 4.5.7 was fitted (*resolution*: clamp)
    stiction: float = 3.6  # N, average static friction (§4)
    ccw_coulomb_scale: float = 1.0  # F_c multiplier moving towards 0 deg (direction-dependent variant)

    def __post_init__(self) -> None:
        if self.viscous < 0 or self.stiction < 0 or self.ccw_coulomb_scale < 0:
            raise InvalidParameter("friction coefficients must be non-negative")
        if not self.fit_range[0] < self.fit_range[1]:
            raise InvalidParameter(f"fit_range must be increasing, got {self.fit_range}")


@dataclasses.dataclass(frozen=True)
class SupplyParams:
    """Water supply (§3); the thesis plant holds it constant."""

    pressure: float = 300e3  # Pa gauge, nominal P_ws
    max_pressure: float = 738e3  # Pa, air-over-water at its limit (1.19 x 620 kPa)

    def __post_init__(self) -> None:
        _require_positive(self, "pressure", "max_pressure")


@dataclasses.dataclass(frozen=True)
class SensorParams:
    """Hall position and pressure sensors, sampled at 1 ms (§5)."""

    sample_period: float = 1e-3  # s
    position_noise: float = 0.02e-3  # m, white, uniform within +-this bound
    pressure_noise: float = 0.4e3  # Pa, white, uniform within +-this bound

    def __post_init__(self) -> None:
        _require_positive(self, "sample_period")
        if self.position_noise < 0 or self.pressure_noise < 0:
            raise InvalidParameter("sensor noise bounds must be non-negative")


@dataclasses.dataclass(frozen=True)
class ObserverParams:
    """First-order velocity/acceleration observer (eq. 5.2.2)."""

    gain: float = 100.0  # 1/s, K_OB; not given by the thesis (*inferred*: 16 Hz, below the 31 Hz control Nyquist)

    def __post_init__(self) -> None:
        _require_positive(self, "gain")


@dataclasses.dataclass(frozen=True)
class JointParams:
    """The whole joint: one typed place for every SPEC number."""

    cylinder: CylinderParams = CylinderParams()
    gears: GearParams = GearParams()
    masses: MassParams = MassParams()
    valves: ValveParams = ValveParams()
    friction: FrictionParams = FrictionParams()
    supply: SupplyParams = SupplyParams()
    sensors: SensorParams = SensorParams()
    observer: ObserverParams = ObserverParams()
    gravity: float = 9.81  # m/s^2


NOMINAL_PARAMS = JointParams()  # every SPEC value, unmodified
