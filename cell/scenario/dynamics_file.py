"""The rigid-body model file (``mintime.dynamics_file``, e.g. ``microbot_dynamics.yaml``).

Validated like a scenario (pydantic models; one line naming file, key and value
for any problem) and turned into the plain :class:`cell.arm.dynamics.DynamicsModel`
the maths uses.  Read once per version of the file.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import Field, ValidationError

from cell.arm.dynamics import Drives, DynamicsModel, Electrical, Links
from cell.plumbing.cache import file_key, memo
from cell.plumbing.errors import ScenarioError
from cell.scenario.fields import Section, error_from_validation

Mass = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=0.0, le=1e4)]
Metres = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=-100.0, le=100.0)]
Positive = Annotated[float, Field(strict=True, allow_inf_nan=False, gt=0.0, le=1e6)]
NonNegative = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=0.0, le=1e6)]
PositiveFive = tuple[Positive, Positive, Positive, Positive, Positive]
NonNegativeFive = tuple[NonNegative, NonNegative, NonNegative, NonNegative, NonNegative]
Xyz = tuple[Metres, Metres, Metres]
Moments = tuple[NonNegative, NonNegative, NonNegative]
Efficiency = Annotated[float, Field(strict=True, allow_inf_nan=False, gt=0.0, le=1.0)]


class LinksFile(Section):
    """Mass properties of links 1-5, each in its own DH frame."""

    mass_kg: tuple[Mass, Mass, Mass, Mass, Mass] = Links.mass_kg
    com_m: tuple[Xyz, Xyz, Xyz, Xyz, Xyz] = Links.com_m
    """Centre of mass of each link in its own frame."""
    inertia_kg_m2: tuple[Moments, Moments, Moments, Moments, Moments] = Links.inertia_kg_m2
    """Principal moments (Ixx, Iyy, Izz) about the centre of mass."""


class DrivesFile(Section):
    """Stepper drives as seen at the joints."""

    gear_ratio: PositiveFive = Drives.gear_ratio
    rotor_inertia_kg_m2: NonNegativeFive = Drives.rotor_inertia_kg_m2
    stall_torque_nm: PositiveFive = Drives.stall_torque_nm
    viscous_nm_s_rad: NonNegativeFive = Drives.viscous_nm_s_rad


class ElectricalFile(Section):
    """What the stepper drives draw from their supply (every value an assumption)."""

    supply_v: Positive = Electrical.supply_v
    winding_ohm: PositiveFive = Electrical.winding_ohm
    phases_on: float = Field(Electrical.phases_on, strict=True, allow_inf_nan=False, ge=0.0,
                             le=2.0)
    motion_efficiency: tuple[Efficiency, Efficiency, Efficiency, Efficiency, Efficiency] = \
        Electrical.motion_efficiency
    recover_braking: bool = Field(Electrical.recover_braking, strict=True)


class DynamicsFile(Section):
    """A rigid-body model file."""

    name: str = "microbot"
    description: str = ""
    gravity_m_s2: float = Field(9.80665, strict=True, allow_inf_nan=False, ge=0.0, le=100.0)
    links: LinksFile = LinksFile()
    drives: DrivesFile = DrivesFile()
    electrical: ElectricalFile = ElectricalFile()


def load_dynamics(path: str | Path) -> DynamicsModel:
    """Read and validate a dynamics file (errors name the file, key and value)."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(path, "(file)", str(path), "no such dynamics file")
    return _load(path)


@memo(key=file_key)
def _load(path: Path) -> DynamicsModel:
    from cell.scenario import catalog
    from cell.scenario.yamlio import load_mapping

    raw = load_mapping(path, "dynamics")
    catalog.refuse_other_kind(raw, path, "dynamics")
    try:
        f = DynamicsFile.model_validate(raw)
    except ValidationError as exc:
        raise error_from_validation(exc, raw, path, DynamicsFile) from None
    return DynamicsModel(f.name, f.description, f.gravity_m_s2,
                         Links(f.links.mass_kg, f.links.com_m, f.links.inertia_kg_m2),
                         Drives(f.drives.gear_ratio, f.drives.rotor_inertia_kg_m2,
                                f.drives.stall_torque_nm, f.drives.viscous_nm_s_rad),
                         Electrical(f.electrical.supply_v, f.electrical.winding_ohm,
                                    f.electrical.phases_on, f.electrical.motion_efficiency,
                                    f.electrical.recover_braking))
