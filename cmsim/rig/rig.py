"""A complete transmission or bearing test rig: its components and its degrees of freedom.

Every class of :mod:`cmsim.rig` is a frozen dataclass in SI units (m, kg, N, s, rad, Pa·s);
field names carry the unit. Build variants with :func:`dataclasses.replace` or the ``with_*``
helpers, never by mutation. :meth:`Rig.paper_2016` holds Tables 1-3 of Fernandez-del-Rincon
et al. (2016).

Two topologies are supported:

* a gear rig: two shafts (``1`` driving, ``2`` driven), each ``b1 - G1 - b2`` on two ball
  bearings, one spur-gear pair, an imposed input speed through a torsional coupling on
  ``1b1`` and a load torque on an output inertia ``2J2`` coupled to ``2b2`` (19 DOF);
* a bearing rig: one shaft ``b1 - D1 - b2`` carrying a rotor disk, driven at constant speed,
  with a static radial load on the disk (9 DOF) — e.g. the CWRU and MFPT test rigs.

The DOFs are ordered as in the paper's eq. 1: ``x, y, θ`` of each node in
:attr:`Rig.node_names` order, then ``θ_2J2`` on a gear rig (:meth:`Rig.dof_index`).

References
----------
.. [1] A. Fernandez-del-Rincon et al., "Enhanced model of gear transmission dynamics for
   condition monitoring applications: effects of torque, friction and bearing clearance",
   MSSP 85 (2017) 445-467 (preprint 2016), Tables 1-3.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import tomli_w

from cmsim._io import atomic_write_text
from cmsim.errors import ParameterError, check_choice, check_range
from cmsim.rig.bearing import RollingBearing
from cmsim.rig.codec import drop_none, from_plain, to_plain
from cmsim.rig.contact import Lubricant, MeshContact
from cmsim.rig.gears import GearPair, SpurGear
from cmsim.rig.housing import HousingPath
from cmsim.rig.ranges import MAX_INERTIA_KG_M2
from cmsim.rig.shafts import Coupling, ShaftLine

__all__ = ["Rig", "RIG_FORMAT_VERSION", "AXES"]

#: Version written in a rig file; :meth:`Rig.load` refuses other versions.
RIG_FORMAT_VERSION = 1

#: The three DOFs of a node, in order.
AXES = ("x", "y", "theta")


@dataclass(frozen=True)
class Rig:
    """A complete transmission (gear rig) or bearing test rig.

    Attributes
    ----------
    name : str
        Free-text name.
    shafts : tuple of ShaftLine
        Shaft 1 (driving), and shaft 2 (driven) when there are gears.
    gears : GearPair or None
        The spur-gear pair; ``None`` for a bearing rig with one shaft.
    input_coupling : Coupling
        Coupling between the imposed input rotation and node 1b1.
    output_coupling : Coupling or None
        Coupling between node 2b2 and the output inertia 2J2 (gear rigs).
    output_inertia_kg_m2 : float or None
        Output inertia J_2J2 carrying the load torque (gear rigs), kg·m².
    lubricant : Lubricant
        Oil between the teeth.
    mesh_contact : MeshContact
        Friction and damping of the tooth contact.
    housing : HousingPath
        Transfer path from bearing forces to housing accelerations (the sensor model of
        :mod:`cmsim.sensors`); a rig file without it gets the documented defaults.
    """

    name: str
    shafts: tuple[ShaftLine, ...]
    gears: GearPair | None = None
    input_coupling: Coupling = field(default_factory=Coupling)
    output_coupling: Coupling | None = None
    output_inertia_kg_m2: float | None = None
    lubricant: Lubricant = field(default_factory=Lubricant)
    mesh_contact: MeshContact = field(default_factory=MeshContact)
    housing: HousingPath = field(default_factory=HousingPath)

    def __post_init__(self):
        object.__setattr__(self, "shafts", tuple(self.shafts))
        if self.gears is not None:
            if len(self.shafts) != 2:
                raise ParameterError("a gear rig needs exactly 2 shafts (driving, driven)")
            if self.output_coupling is None or self.output_inertia_kg_m2 is None:
                raise ParameterError("a gear rig needs output_coupling and output_inertia_kg_m2")
            check_range("output_inertia_kg_m2", self.output_inertia_kg_m2, 0.0,
                        MAX_INERTIA_KG_M2, lo_open=True, unit="kg m^2")
            for i, s in enumerate(self.shafts):
                if s.rotor is not None:
                    raise ParameterError(f"shaft {i + 1} of a gear rig carries the gear; "
                                         "rotor must be None")
        else:
            if len(self.shafts) != 1:
                raise ParameterError("a rig without gears has exactly 1 shaft")
            if self.shafts[0].rotor is None:
                raise ParameterError("a rig without gears needs shafts[0].rotor (the disk)")

    # ------------------------------------------------------------------ topology
    @property
    def has_gears(self):
        """True for a gear rig."""
        return self.gears is not None

    @property
    def _shaft_nodes(self):
        """Node suffixes along a shaft: bearing 1, centre (gear or disk), bearing 2."""
        return ("b1", "G1" if self.has_gears else "D1", "b2")

    @property
    def node_names(self):
        """Names of the 3-DOF nodes in DOF order, e.g. ``('1b1', '1G1', '1b2', ...)``."""
        return tuple(f"{s}{n}" for s in range(1, len(self.shafts) + 1)
                     for n in self._shaft_nodes)

    def dof_index(self, node, axis="x"):
        """Index of a DOF in the state vector.

        Parameters
        ----------
        node : str
            A node of :attr:`node_names` (``"1b1"``), or ``"2J2"`` (the output inertia of a
            gear rig, rotation only).
        axis : str
            ``"x"``, ``"y"`` or ``"theta"`` (:data:`AXES`).

        Examples
        --------
        >>> rig = Rig.paper_2016()
        >>> [rig.dof_index(node, "theta") for node in ("1G1", "2b2", "2J2")]
        [5, 17, 18]
        """
        check_choice("axis", axis, AXES)
        if node == "2J2" and self.has_gears and axis == "theta":
            return self.n_dof - 1
        try:
            return 3 * self.node_names.index(node) + AXES.index(axis)
        except ValueError:
            raise ParameterError(f"node must be one of {self.node_names}"
                                 f"{' or 2J2 (theta)' if self.has_gears else ''}, got {node!r}",
                                 param="node") from None

    @staticmethod
    def shaft_of(node):
        """The shaft (1, 2, ...) a node of :attr:`node_names` sits on, or None for a name
        that is not one (a sensor on no node).

        Examples
        --------
        >>> Rig.shaft_of("2b1"), Rig.shaft_of("1G1"), Rig.shaft_of("housing")
        (2, 1, None)
        """
        m = re.match(r"(\d+)[A-Za-z]", str(node))
        return int(m.group(1)) if m else None

    @property
    def bearing_names(self):
        """Names of the bearing nodes, e.g. ``('1b1', '1b2', '2b1', '2b2')``."""
        return tuple(n for n in self.node_names if "b" in n)

    @property
    def bearings(self):
        """Bearings in the order of :attr:`bearing_names`."""
        return tuple(b for s in self.shafts for b in s.bearings)

    @property
    def dof_masses(self):
        """Diagonal of the mass matrix in DOF order (x, y, θ of each node, then θ_2J2):
        kg for translations, kg·m² for rotations, shape (n_dof,)."""
        masses = []
        for i, shaft in enumerate(self.shafts):
            if self.gears is not None:
                gear = self.gears.driving if i == 0 else self.gears.driven
                centre = (gear.mass_kg, gear.inertia_kg_m2)
            else:
                centre = (shaft.rotor.mass_kg, shaft.rotor.inertia_kg_m2)
            for mass, inertia in ((shaft.bearing_1.mass_kg, shaft.bearing_1.inertia_kg_m2),
                                  centre,
                                  (shaft.bearing_2.mass_kg, shaft.bearing_2.inertia_kg_m2)):
                masses += [mass, mass, inertia]
        if self.gears is not None:
            masses.append(self.output_inertia_kg_m2)
        return np.array(masses, dtype=float)

    def spring_elements(self, bearing_dampers=True):
        """Linear spring-dampers of Annex A in DOF indices: list of (a, b, k, c), b = −1 for
        a spring to ground (k in N/m or N·m/rad, c in N·s/m or N·m·s/rad).

        Shaft segments (x, y, θ between bearing and centre nodes), the bearings' dampers to
        the housing (``bearing_dampers``; their forces are part of the recorded housing
        forces), the input coupling (a spring to ground in deviation coordinates: the input
        rotation is imposed) and, on a gear rig, the output coupling to θ_2J2.
        """
        elements = []
        for s, shaft in enumerate(self.shafts, start=1):
            b1, c, b2 = (self.dof_index(f"{s}{n}", "x") for n in self._shaft_nodes)
            for seg, (na, nb) in enumerate(((b1, c), (c, b2))):
                for d in (0, 1):
                    elements.append((na + d, nb + d, shaft.flexural_stiffness_n_per_m[seg],
                                     shaft.flexural_damping_n_s_per_m[seg]))
                elements.append((na + 2, nb + 2, shaft.torsional_stiffness_nm_per_rad[seg],
                                 shaft.torsional_damping_nm_s_per_rad[seg]))
            if bearing_dampers:
                for node, brg in ((b1, shaft.bearing_1), (b2, shaft.bearing_2)):
                    for d in (0, 1):
                        elements.append((node + d, -1, 0.0, brg.damping_n_s_per_m))
        elements.append((self.dof_index("1b1", "theta"), -1,
                         self.input_coupling.stiffness_nm_per_rad,
                         self.input_coupling.damping_nm_s_per_rad))
        if self.gears is not None:
            elements.append((self.dof_index("2b2", "theta"), self.dof_index("2J2", "theta"),
                             self.output_coupling.stiffness_nm_per_rad,
                             self.output_coupling.damping_nm_s_per_rad))
        return elements

    @property
    def n_dof(self):
        """Number of degrees of freedom (19 for the paper rig, 9 for a bearing rig)."""
        return 3 * len(self.node_names) + (1 if self.has_gears else 0)

    # ------------------------------------------------------------------ variants
    def with_clearance(self, clearance_m):
        """Same rig with every bearing's radial clearance set to ``clearance_m`` (m)."""
        shafts = tuple(replace(s, bearing_1=replace(s.bearing_1, clearance_m=clearance_m),
                               bearing_2=replace(s.bearing_2, clearance_m=clearance_m))
                       for s in self.shafts)
        return replace(self, shafts=shafts)

    def with_friction(self, friction_coefficient):
        """Same rig with mesh friction coefficient ``friction_coefficient``."""
        return replace(self, mesh_contact=replace(self.mesh_contact,
                                                  friction_coefficient=friction_coefficient))

    # ------------------------------------------------------------------ presets
    @classmethod
    def paper_2016(cls):
        """The rig of Fernandez-del-Rincon et al. (2016), Tables 1-3.

        Bearing 209 with raceway *diameters* 52.291/77.706 mm, c = 0.015 mm (see
        papers/NOTES.md), free contact angle ≈ 9.9° from the groove geometry; J_1b1 = J_2b2 =
        9.9e-5 kg·m² as printed (9.8e-5 would match modes 16-19 to 0.02 %).
        """
        gear = SpurGear(n_teeth=28, module_m=3.175e-3, face_width_m=6.35e-3,
                        pressure_angle_rad=math.radians(20), rack_addendum_coef=1.25,
                        rack_dedendum_coef=1.0, rack_tip_radius_coef=0.25, tip_radius_coef=0.05,
                        bore_radius_m=0.020, mass_kg=0.79999, inertia_kg_m2=4.0408e-4,
                        youngs_modulus_pa=210e9, poisson_ratio=0.3)

        def brg(mass, inertia):
            return RollingBearing(n_balls=9, ball_diameter_m=12.7e-3,
                                  inner_raceway_diameter_m=52.291e-3,
                                  outer_raceway_diameter_m=77.706e-3,
                                  inner_groove_radius_m=6.6e-3, outer_groove_radius_m=6.6e-3,
                                  clearance_m=0.015e-3, mass_kg=mass, inertia_kg_m2=inertia,
                                  damping_n_s_per_m=334.27)

        heavy, light = brg(0.4901, 9.9e-5), brg(0.245, 4.9e-5)
        shaft_kw = dict(flexural_stiffness_n_per_m=(6.24e8, 6.24e8),
                        flexural_damping_n_s_per_m=(31.6, 31.6),
                        torsional_stiffness_nm_per_rad=(4.0e5, 4.0e5),
                        torsional_damping_nm_s_per_rad=(0.0, 0.0))
        return cls(
            name="Fernandez-del-Rincon et al. 2016 (Tables 1-3)",
            shafts=(ShaftLine(bearing_1=heavy, bearing_2=light, **shaft_kw),
                    ShaftLine(bearing_1=light, bearing_2=heavy, **shaft_kw)),
            gears=GearPair(driving=gear, driven=gear),
            input_coupling=Coupling(4.0e5, 3.5761),
            output_coupling=Coupling(4.0e5, 3.5761),
            output_inertia_kg_m2=3.56e-4,
            lubricant=Lubricant(0.004),
            mesh_contact=MeshContact(),
        )

    @classmethod
    def rotor_on_bearings(cls, bearing, rotor, *, name="rotor on two ball bearings",
                          bearing_2=None, shaft_stiffness_n_per_m=(2.0e8, 2.0e8),
                          shaft_damping_n_s_per_m=(30.0, 30.0),
                          torsional_stiffness_nm_per_rad=(1.0e5, 1.0e5),
                          input_coupling=None):
        """A bearing test rig: one shaft ``1b1 - 1D1 - 1b2`` carrying a rotor, no gears.

        Driven at constant speed through ``input_coupling``; load it with
        :attr:`OperatingPoint.radial_load_n`.

        Parameters
        ----------
        bearing : RollingBearing
            Bearing at node 1b1 (and at 1b2 unless ``bearing_2`` is given).
        rotor : Rotor
            Disk at the centre node 1D1.
        name : str
            Free-text name.
        bearing_2 : RollingBearing, optional
            Bearing at node 1b2; default ``bearing``.
        shaft_stiffness_n_per_m, shaft_damping_n_s_per_m : tuple of float
            Flexural stiffness (N/m) and damping (N·s/m) of the two shaft segments.
        torsional_stiffness_nm_per_rad : tuple of float
            Torsional stiffness of the two segments, N·m/rad.
        input_coupling : Coupling, optional
            Coupling to the imposed input rotation; default :class:`Coupling`'s.
        """
        shaft = ShaftLine(bearing_1=bearing, bearing_2=bearing if bearing_2 is None else bearing_2,
                          flexural_stiffness_n_per_m=shaft_stiffness_n_per_m,
                          flexural_damping_n_s_per_m=shaft_damping_n_s_per_m,
                          torsional_stiffness_nm_per_rad=torsional_stiffness_nm_per_rad,
                          torsional_damping_nm_s_per_rad=(0.0, 0.0), rotor=rotor)
        return cls(name=name, shafts=(shaft,),
                   input_coupling=Coupling() if input_coupling is None else input_coupling)

    # ------------------------------------------------------------------ TOML
    def to_dict(self):
        """Plain nested dict (SI values) with a format version."""
        d = to_plain(self)
        d["format_version"] = RIG_FORMAT_VERSION
        return d

    @classmethod
    def from_dict(cls, data):
        """Rig from :meth:`to_dict` output; unknown keys raise :class:`ParameterError`.

        Keys ending in ``_deg`` or ``_mm`` are converted explicitly to the ``_rad`` / ``_m``
        fields of the same stem (:mod:`cmsim.rig.codec`).

        Parameters
        ----------
        data : dict
            Nested tables of the fields, with an optional ``format_version`` (a
            ``faults`` list is left to :func:`cmsim.faults.load_faults`).
        """
        data = dict(data)
        if isinstance(data.get("machine"), dict):
            raise ParameterError("a machine file (cmsim calibrate writes them), not a rig: "
                                 "give it to --machine")
        data.pop("faults", None)     # a [[faults]] list: read by cmsim.faults.load_faults
        version = data.pop("format_version", RIG_FORMAT_VERSION)
        if version != RIG_FORMAT_VERSION:
            raise ParameterError(f"rig format_version {version} is not supported "
                                 f"(this cmsim reads version {RIG_FORMAT_VERSION})")
        return from_plain(cls, data, "rig")

    def save(self, path, faults=()):
        """Write the rig as TOML (atomically), with an optional ``[[faults]]`` list.

        Parameters
        ----------
        path : str or pathlib.Path
            The file to write.
        faults : sequence
            :mod:`cmsim.faults` values (anything with ``to_dict()``); read them back with
            :func:`cmsim.faults.load_faults` (:meth:`load` ignores the list).
        """
        data = drop_none(self.to_dict())
        if faults:
            data["faults"] = [drop_none(f.to_dict()) for f in faults]
        text = ("# cmsim rig description — auto-generated, SI units (m, kg, N, s, rad).\n"
                "# Keys ending in _deg or _mm are accepted on reading and converted.\n"
                + tomli_w.dumps(data))
        atomic_write_text(Path(path), text)

    @classmethod
    def load(cls, path):
        """Read a rig written by :meth:`save` (or by hand in the same layout).

        Parameters
        ----------
        path : str or pathlib.Path
            A TOML rig file.

        Raises
        ------
        ParameterError
            The file is missing, unreadable, not TOML, or holds a bad key or value; the
            message names the file and (as ``detail``) what is wrong.
        """
        path = Path(path)

        def refuse(detail):
            err = ParameterError(f"rig file {path}: {detail}", param="rig")
            err.detail = detail
            return err

        try:
            with path.open("rb") as fh:
                data = tomllib.load(fh)
        except FileNotFoundError:
            raise refuse("does not exist") from None
        except IsADirectoryError:
            raise refuse("is a directory, not a TOML file") from None
        except OSError as exc:
            raise refuse(f"cannot be read ({exc.strerror or exc})") from None
        except UnicodeDecodeError:
            raise refuse("is not a text (TOML) file") from None
        except tomllib.TOMLDecodeError as exc:
            raise refuse(f"is not valid TOML: {exc}") from None
        try:
            return cls.from_dict(data)
        except ParameterError as exc:
            raise refuse(str(exc)) from None
