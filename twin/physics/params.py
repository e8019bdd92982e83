"""Every physical parameter of the joint, in SI units, with its source.

Sections (§) refer to ``docs/model.md`` (cited as "SPEC §N"); equation numbers are the thesis's.
Conversions to mm, degrees, grams and kPa happen only at the user-facing edge (CLI, tables, plots).
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
class SolenoidParams:
    """The solenoid valve's coil and plunger (:mod:`twin.physics.solenoid`), dimensionless where the
    thesis gives nothing to scale by. The thesis gives none of these: they are fitted
    (``python -m twin.experiments.valve_fit``) so that the valve test replica (§4.4.3, SPEC §3) gives
    eq. 4.4.2's R(d), the 5 ms opening and 2 ms closing delays, and no flow from a 25 % pulse."""

    coil_time_constant_on: float = 3.401e-3  # s, L / R while the coil is driven
    coil_time_constant_off: float = 1.768e-3  # s, current decay after switch-off (through the suppressor)
    force_ratio: float = 8.838  # f_m: magnetic force at full current with the valve open (smallest gap), over the spring preload
    gap_ratio: float = 1.071  # kappa: magnetic gap with the valve shut over the gap left when open, minus 1
    spring_ratio: float = 0.6866  # k: spring force gained over the full travel, over its preload
    natural_frequency: float = 10380.0  # rad/s, w = sqrt(preload / (plunger mass x travel))
    damping_ratio: float = 1.576  # zeta, of the plunger in water
    step: float = 5e-6  # s, integration step (converged: halving it changes R(d) by < 1 %, a test checks)

    def __post_init__(self) -> None:
        _require_positive(self, "coil_time_constant_on", "coil_time_constant_off", "natural_frequency",
                          "damping_ratio", "step")
        if self.force_ratio <= 1.0:
            raise InvalidParameter(f"force_ratio must exceed 1 (the coil must lift the plunger), got {self.force_ratio}")
        if self.gap_ratio < 0 or self.spring_ratio < 0:
            raise InvalidParameter("gap_ratio and spring_ratio must be non-negative")


@dataclasses.dataclass(frozen=True)
class ValveParams:
    """On/off solenoid valves, pulse-width-modulated (§3) and eq. 4.4.2."""

    pwm_period: float = 16e-3  # s, 62.5 Hz
    switching_period: float = 1e-3  # s, the DAQ's output tick (§5, §6): duties realised in whole ticks; 0 = continuous
    opening_delay: float = 5e-3  # s
    closing_delay: float = 2e-3  # s
    dead_zone_duty: float = 30.0  # %, below it the real valve does not open
    # §3: only the discharge valve is pulse-width-modulated, the pair's supply valve "stays fully on". True: it
    # stays on while the discharge valve gets no pulse that opens it (|u| in the dead zone, or below half a 1 ms
    # step); False: the pair is shut together, the thesis's model. An incompressible joint hardly moves
    # differently (no flow either way; the held valve only squeezes the locked train: <= 4e-4 deg).
    supply_held_in_dead_zone: bool = False
    resistance_coefficient: float = 1.8372e14  # Pa s/m^3 at d = 1 % (eq. 4.4.2, *resolution*: Pa s/m^3)
    resistance_exponent: float = -2.1706  # eq. 4.4.2
    # The solenoid valve's coil and plunger, for the ``solenoid`` valve model (the others ignore it).
    solenoid: SolenoidParams = dataclasses.field(default_factory=SolenoidParams)

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
class ValveTestRigParams:
    """The valve test of §4.4.3: one valve between a set pressure and atmosphere, PWM at 16 ms."""

    pressure_drops: tuple[float, ...] = (100e3, 200e3, 300e3, 400e3, 500e3)  # Pa (*inferred*: the text's range)
    inertance_time: float = 1.417e-3  # s, tau_I = I / R(100 %) of the rig's water column (fitted with SolenoidParams)
    min_measurable_flow: float = 1e-6  # m^3/s, below it the thesis could not measure flow (§3)


@dataclasses.dataclass(frozen=True)
class FrictionParams:
    """Force loss F_l = F_c(y) sgn(v) + F_v v (eqs. 4.5.5 and 4.5.7)."""

    viscous: float = 45.9  # N s/m, F_v (eq. 4.5.5)
    # eq. 4.5.7, y in metres, highest power first; F_c in N.
    coulomb_poly: tuple[float, ...] = (-3.051e14, 1.587e13, -3.244e11, 3.294e9, -1.727e7, 4.36e4, -39.551)
    fit_range: tuple[float, float] = (2e-3, 14.5e-3)  # m, where eq. 4.5.7 was fitted (*resolution*: clamp)
    stiction: float = 3.6  # N, average static friction (§4)
    ccw_coulomb_scale: float = 1.0  # F_c multiplier moving towards 0 deg (direction-dependent variant)
    # N of dry friction per N of load the gear train carries besides its own (gravity through the gears,
    # referred to the rack): the meshes', the rack guides' and the bushings' friction grows with the load
    # they transmit. The §4.5.1 friction tests (eq. 4.5.7) ran horizontal without payload, so none of it
    # is in F_c. The thesis plant has none (0); the as-built plant fits it (twin.plants.as_built.FITTED).
    load_friction: float = 0.0

    def __post_init__(self) -> None:
        if self.viscous < 0 or self.stiction < 0 or self.ccw_coulomb_scale < 0 or self.load_friction < 0:
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


OBSERVER_KINDS = ("first-order", "kalman")


@dataclasses.dataclass(frozen=True)
class ObserverParams:
    """The velocity/acceleration observer: first-order (eq. 5.2.2), or a Kalman filter on the nominal model."""

    # 1/s, K_OB; not given by the thesis (*inferred* for the thesis plant: 16 Hz, below the 31 Hz control Nyquist;
    # the as-built plant fits it, twin.plants.as_built.FITTED)
    gain: float = 100.0
    kind: str = "first-order"  # "first-order" (eq. 5.2.2) or "kalman" (twin.physics.sensing.KalmanObserver, SPEC §10)
    # Kalman only: spectral density of the unmodelled acceleration's rate (random walk), (m/s^3)^2 s. A design
    # choice (not from the thesis) that sets how fast the filter follows friction and gravity: 3e3 gave the least
    # velocity error on the committed as-built plant, T1-T4, both controllers, seed 0, in a scan of 1e2-1e8 (flat
    # from 1e3 to 1e4), with the lumped and again with the referred mass.
    disturbance_density: float = 3e3

    def __post_init__(self) -> None:
        _require_positive(self, "gain", "disturbance_density")
        if self.kind not in OBSERVER_KINDS:
            raise InvalidParameter(f"observer kind must be one of {', '.join(OBSERVER_KINDS)}, got {self.kind!r}")


AIR_FRACTION_MAX = 0.2  # free air per chamber volume the chamber model takes: past it, more air than a water joint


@dataclasses.dataclass(frozen=True)
class ChamberParams:
    """Compressible chambers (as-built; §3: "trapped air lowers" beta).

    Off (``compressible=False``) the water is incompressible and a sealed
    chamber locks the joint, as the thesis modelled it. On, each chamber's
    pressure is a state: dP/dt = beta_eff(P) / V(y) (Q_in - Q_out -+ A v), with
    free air (isothermal) lowering the bulk modulus at low pressure:
    1 / beta_eff = 1 / beta_w + x_air p_atm / p_abs^2.
    """

    compressible: bool = False
    water_bulk_modulus: float = 2.19e9  # Pa, beta of water (§3)
    air_fraction: float = 0.0  # x_air: free air volume per chamber volume at atmospheric pressure (calibrated)
    dead_volume: float = 0.3e-6  # m^3 per chamber at the end of stroke: ports, hose to the valves (*assumed*)
    leak_conductance: float = 0.0  # m^3/(Pa s) past each discharge valve to the tank: a closed chamber relaxes
    initial_pressure_fraction: float = 0.5  # gauge, of the supply, in both chambers at the start: the thesis does not
    # say; the as-built plant fits it (twin.plants.as_built.FITTED; assumed half the supply until 2026-11-28)
    atmospheric_pressure: float = 101.325e3  # Pa
    substeps: int = 100  # implicit sub-steps of the chamber/rack/supply model per physics tick (10 us)

    def __post_init__(self) -> None:
        _require_positive(self, "water_bulk_modulus", "dead_volume", "atmospheric_pressure")
        if not 0.0 <= self.air_fraction <= AIR_FRACTION_MAX:
            raise InvalidParameter(f"air_fraction must be in [0, {AIR_FRACTION_MAX}], got {self.air_fraction}")
        if self.leak_conductance < 0 or self.substeps < 1:
            raise InvalidParameter("leak_conductance must be >= 0 and substeps >= 1")
        if not 0.0 <= self.initial_pressure_fraction <= 1.0:  # between the tank's pressure and the supply's
            raise InvalidParameter(f"initial_pressure_fraction must be in [0, 1] of the supply, got "
                                   f"{self.initial_pressure_fraction}")


@dataclasses.dataclass(frozen=True)
class SupplyLineParams:
    """The supply between the air-over-water cylinder and the valves (as-built; §3, §10).

    ``model``: ``constant`` (the thesis: P_ws fixed); ``line`` (the air-over-water
    cylinder feeding the valves through a hose: series resistance R and inertance L
    into a compliance C at the valve block, so the pressure there sags while water
    flows, rings at f_n = 1 / (2 pi sqrt(L C)) and recovers when flow stops);
    ``accumulator`` (the same line with a gas accumulator of ``accumulator_compliance``
    added at the valve block, thesis future work 1).
    """

    model: str = "constant"
    compliance: float = 2e-13  # m^3/Pa, C: hose wall and water at the valve block (assumed)
    natural_frequency: float = 60.0  # Hz, f_n of the line with C (assumed)
    damping_ratio: float = 0.3  # zeta of the line with C (assumed)
    accumulator_compliance: float = 2e-11  # m^3/Pa, a 10 mL gas accumulator at 400 kPa abs (V / (gamma p))

    def __post_init__(self) -> None:
        if self.model not in ("constant", "line", "accumulator"):
            raise InvalidParameter(f"supply model must be constant, line or accumulator, got {self.model!r}")
        _require_positive(self, "compliance", "natural_frequency", "accumulator_compliance")
        if not self.damping_ratio > 0:
            raise InvalidParameter(f"damping_ratio must be positive, got {self.damping_ratio}")

    @property
    def inertance(self) -> float:
        """L = 1 / (omega_n^2 C) in Pa s^2/m^3."""
        return 1.0 / ((2.0 * math.pi * self.natural_frequency) ** 2 * self.compliance)

    @property
    def resistance(self) -> float:
        """R = 2 zeta sqrt(L / C) in Pa s/m^3."""
        return 2.0 * self.damping_ratio * math.sqrt(self.inertance / self.compliance)


@dataclasses.dataclass(frozen=True)
class HallParams:
    """What the Hall sensor reading is in the as-built joint (§5).

    ``calibration_error``: the DAQ turns volts into degrees with the quadratic
    fit eq. 4.2.1, but the sensor's true volts-angle curve is the one through the
    measured calibration points (piecewise linear between them), so the reading
    is off by the fit's residual (up to a few degrees).
    """

    calibration_error: bool = False
    fit: tuple[float, float, float] = (-9.122, -25.58, 244.94)  # deg = a x^2 + b x + c, x in V (eq. 4.2.1)
    # (deg, V) measured calibration points (§5); protractor accuracy +-0.5 deg.
    points: tuple[tuple[float, float], ...] = (
        (3, 3.866), (24, 3.793), (53, 3.408), (55, 3.378), (66, 3.244), (69, 3.215), (94, 2.866), (97, 2.828),
        (106, 2.711), (125, 2.510), (126, 2.494), (138, 2.320), (156, 2.047), (174, 1.706), (176, 1.671))


@dataclasses.dataclass(frozen=True)
class StictionMapParams:
    """Static friction that varies along the stroke (as-built; thesis future work 2).

    Breakaway force F_s(y) = stiction + scatter u_k, piecewise linear between knots
    ``knot_spacing`` apart over the rack's stroke, u_k uniform in [-1, 1] from
    ``seed``, or, with ``seed=None``, from the run's own seed: the map is not
    known, so an ensemble of runs is an ensemble of plausible joints. scatter = 0:
    a constant F_s.
    """

    scatter: float = 0.0  # N (as-built: assumed 0.5 N)
    knot_spacing: float = 1e-3  # m
    seed: int | None = None  # None: each run draws its own map from its scenario seed (an ensemble of joints)

    def __post_init__(self) -> None:
        _require_positive(self, "knot_spacing")
        if self.scatter < 0:
            raise InvalidParameter(f"stiction scatter must be >= 0, got {self.scatter}")


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
    chambers: ChamberParams = ChamberParams()
    supply_line: SupplyLineParams = SupplyLineParams()
    hall: HallParams = HallParams()
    stiction_map: StictionMapParams = StictionMapParams()
    gravity: float = 9.81  # m/s^2


NOMINAL_PARAMS = JointParams()  # every SPEC value, unmodified
