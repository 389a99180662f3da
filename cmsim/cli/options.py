"""Option groups several commands share, each declared once with its reader.

The defaults come from the library (:data:`cmsim.rig.SAMPLING`, the rig's own values) and
the ranges from :data:`cmsim.rig.RANGES`, so every command and the Python API give the same
default and accept the same range for the same option.
"""

from __future__ import annotations

import re
import sys
from functools import partial

from cmsim.cli.contract import CLIError, load_file, ranged
from cmsim.errors import ParameterError
from cmsim.rig import RANGES, SAMPLING, OperatingPoint, Rig
from cmsim.rig.plausibility import load_warnings

__all__ = ["number", "add_rig_options", "load_rig", "add_sampling_options", "add_mesh_options",
           "mesh_argument", "prepare_tables", "add_fault_options", "faults_of", "add_losses_option",
           "check_losses_options", "resolved_setup", "operating_point", "operating_warnings",
           "add_recording_options", "add_trust_option", "recording_values", "FAULT_NAMES",
           "UNIT_NAMES"]

#: The catalogue's names for --help (cmsim.faults.FAULT_TYPES; not imported at start-up, it
#: pulls in the mesh-stiffness stack; tests check the two agree).
FAULT_NAMES = ("outer_race", "inner_race", "ball", "wear", "off_size_ball", "rolling_slip",
               "eccentricity", "tooth_crack", "tooth_spall", "tooth_breakage", "profile_error",
               "speed_fluctuation", "torque_ripple")


#: The unit table's units for --help (cmsim.measured.schema.known_units(); not imported at
#: start-up, it pulls in the measured stack; tests check the two agree).
UNIT_NAMES = ("g", "m/s2", "m/s^2", "m/s²", "mm/s2", "mm/s^2", "m/s", "mm/s", "in/s", "ips",
              "m", "mm", "um", "µm", "mil", "V", "mV")


def number(name):
    """argparse type of the quantity ``name`` of :data:`cmsim.rig.RANGES`."""
    return ranged(RANGES[name])


# ---------------------------------------------------------------------- rig
def add_rig_options(p, *, friction=True, many=False):
    """Add ``--rig``, ``--clearance-m`` and (with ``friction``) ``--friction`` to the parser
    ``p``; with ``many`` the last two take lists (a sweep varies them)."""
    p.add_argument("--rig", metavar="FILE.toml",
                   help="rig description (default: the paper's rig, Tables 1-3)")
    nargs = "+" if many else None
    p.add_argument("--clearance-m", type=number("clearance_m"), nargs=nargs, metavar="C",
                   help="radial clearance of every bearing, m (negative = preload; default: "
                        "the rig's)")
    if friction:
        p.add_argument("--friction", type=number("friction"), nargs=nargs, metavar="F",
                       help="mesh friction coefficient (paper: 0, 0.03, 0.05; default: the "
                            "rig's)")


def load_rig(args, *, variants=True):
    """The rig of ``args.rig`` (default the paper's), with ``--clearance-m`` and
    ``--friction`` applied unless ``variants`` is False (a sweep varies them)."""
    rig = load_file("--rig", args.rig, Rig.load, "a rig TOML file") if args.rig \
        else Rig.paper_2016()
    if not variants:
        return rig
    if getattr(args, "clearance_m", None) is not None:
        rig = rig.with_clearance(args.clearance_m)
    if getattr(args, "friction", None) is not None:
        if rig.gears is None:
            raise CLIError("--friction needs a rig with gears", option="--friction")
        rig = rig.with_friction(args.friction)
    return rig


def operating_warnings(args, rig, op):
    """Warn through ``args.warn`` (:func:`cmsim.rig.plausibility.load_warnings`) about loads
    of ``op`` that ``rig`` cannot carry; the warnings name the options."""
    for text in load_warnings(rig, op):
        args.warn(text)


# ---------------------------------------------------------------------- sampling
def add_sampling_options(p, *, seed_help="seed of every random draw of the run"):
    """Add the one sampling group to the parser ``p``: --duration-s, --fs-hz, --warmup-s,
    --substeps, --seed (its help ``seed_help``), with the library's defaults
    (:data:`cmsim.rig.SAMPLING`)."""
    s = SAMPLING
    p.add_argument("--duration-s", type=number("duration_s"), default=s.duration_s,
                   help=f"recorded duration, s (default {s.duration_s:g})")
    p.add_argument("--fs-hz", type=number("fs_hz"), default=s.fs_hz,
                   help=f"output sample rate, Hz (default {s.fs_hz:g}; any acquisition rate: "
                        "the integration step follows the model, and the record is "
                        "anti-alias filtered)")
    p.add_argument("--warmup-s", type=number("warmup_s"), default=s.warmup_s,
                   help=f"simulated start discarded before recording, s (default "
                        f"{s.warmup_s:g})")
    p.add_argument("--substeps", type=number("substeps"), default=s.substeps,
                   help="integration steps per output sample (default: the fewest giving "
                        ">= 4.7 steps per period of the highest mode and of 6 harmonics of "
                        "the mesh or ball passes; 1 at 75 kHz on the paper rig at 1000 rpm, 3 "
                        "at 25.6 kHz; a value that does not resolve the mesh is refused)")
    p.add_argument("--seed", type=number("seed"), default=s.seed,
                   help=f"{seed_help} (default {s.seed}; recorded in the run)")


# ---------------------------------------------------------------------- mesh
def add_mesh_options(p):
    """Add --mesh, --mesh-table and --table-torque-nm to the parser ``p`` (simulate, modes,
    sweep, losses)."""
    p.add_argument("--mesh", choices=("hybrid-tables", "potential-energy", "hybrid"),
                   help="tooth contact: hybrid FE + Weber-Banaschek tables at the run's torque "
                        "(default; paper model B, shipped for the paper's rig, built and "
                        "cached on first use for other rigs), the load-independent "
                        "potential-energy table (the default through a --machine: its twin's), "
                        "or the contact solved on-line from the FE influence coefficients "
                        "(hybrid: paper model A, ~4x slower)")
    p.add_argument("--mesh-table", metavar="FILE.npz",
                   help="pair stiffness table(s) from cmsim mesh-table instead; the table at "
                        "the run's torque is used (linear in torque between tables)")
    p.add_argument("--table-torque-nm", type=number("torque_nm"), metavar="T",
                   help="use the --mesh-table table of torque T instead (paper model C: "
                        "tables at the wrong torque)")


def mesh_argument(args, rig, torques_nm=(), default="hybrid-tables"):
    """The ``mesh`` value the options in ``args`` name: a string (``default`` without
    --mesh), or the MeshTableSet / table of a file (a gear ``rig`` only).

    A --mesh-table set of several torques is read between its tables only: a torque outside
    its range (--table-torque-nm, or each of ``torques_nm`` without it) is refused, not
    clamped.
    """
    from cmsim.mesh_stiffness.table_set import MeshTableSet

    if args.table_torque_nm is not None and not args.mesh_table:
        raise CLIError("--table-torque-nm selects a table of --mesh-table FILE; give "
                       "--mesh-table too", option="--table-torque-nm")
    if not args.mesh_table:
        return args.mesh or default
    if args.mesh not in (None, "hybrid-tables"):
        raise CLIError(f"--mesh {args.mesh} and --mesh-table exclude each other",
                       option="--mesh")
    if rig.gears is None:
        raise CLIError("--mesh-table needs a rig with gears", option="--mesh-table")
    tables = load_file("--mesh-table", args.mesh_table, MeshTableSet.load,
                       "a mesh stiffness table file (cmsim mesh-table --out)")
    known = [float(t.torque_nm) for t in tables.tables]
    if len(known) > 1:
        lo, hi = min(known), max(known)
        asked = ([("--table-torque-nm", args.table_torque_nm)]
                 if args.table_torque_nm is not None
                 else [("--torque-nm", q) for q in torques_nm])
        for option, q in asked:
            if not lo - 1e-9 * hi <= q <= hi + 1e-9 * hi:
                raise CLIError(f"{option} {q:g} is outside the torques of --mesh-table "
                               f"{args.mesh_table}: allowed [{lo:g}, {hi:g}] N m (tables "
                               f"at {', '.join(f'{x:g}' for x in known)})", option=option)
    return tables if args.table_torque_nm is None else tables.at(args.table_torque_nm)


def prepare_tables(args, rig, mesh, torques_nm=()):
    """Build (or load) the hybrid mesh tables of ``rig`` once when ``mesh`` asks for them —
    the set and the table of each of ``torques_nm`` above it — before a run or the workers
    of a sweep read them from the cache, so a torque the tables cannot take is refused here,
    once. A progress bar shows on a terminal's stderr (never with ``args.json``)."""
    if mesh == "hybrid-tables" and rig.gears is not None:
        from cmsim.dynamics.tooth_contact import hybrid_table_set, resolve_mesh
        progress = None if not args.json and sys.stderr.isatty() else False
        hybrid_table_set(rig, progress=progress)
        for torque in torques_nm:
            resolve_mesh(rig, mesh, torque, progress=progress)


# ---------------------------------------------------------------------- recordings
def add_trust_option(p):
    """Add --trust-metadata to the parser ``p``: every command that reads measured
    recordings (``trust_metadata`` of :func:`cmsim.measured.read_record`)."""
    p.add_argument("--trust-metadata", action="store_true",
                   help="read the stated sample rate and speed as they are: no check "
                        "against the recording's own lines (which refuses a record they "
                        "contradict strongly and warns of a weaker contradiction)")


def add_recording_options(p, *, trust=True):
    """Add --fs-hz, --speed-rpm, --unit, --calibration and (with ``trust``) --trust-metadata
    to the parser ``p``: what a measured recording's file and metadata.json do not state
    (compare, calibrate, spectrum, import; :func:`cmsim.measured.read_record`)."""
    p.add_argument("--fs-hz", type=number("record_fs_hz"), metavar="HZ",
                   help="sample rate of the recording, Hz, when neither the file nor "
                        "metadata.json states it (one they state must agree)")
    p.add_argument("--speed-rpm", type=number("speed_rpm"), metavar="RPM",
                   help="input-shaft speed, rpm: replaces what the file or metadata.json "
                        "states (a warning says so) and is used as given (default: theirs, "
                        "refined from the signal; else found in the signal)")
    p.add_argument("--unit", metavar="UNIT",
                   help="unit of every channel whose file and metadata.json state none (as "
                        "--calibration applies to every channel; one they state must "
                        "agree): " + ", ".join(UNIT_NAMES))
    p.add_argument("--calibration", type=number("calibration"), metavar="C",
                   help="physical units per stored sample value (a WAV in counts or volts), "
                        "when neither the file nor metadata.json states it")
    if trust:
        add_trust_option(p)


def ranged_unit(text):
    """The ``--unit`` ``text`` checked against the unit table
    (:func:`cmsim.measured.schema.checked_unit`); one line naming the option and the
    known units otherwise."""
    from cmsim.measured.schema import checked_unit

    try:
        return checked_unit(text, "--unit")
    except ParameterError as exc:
        raise CLIError(str(exc), option="--unit") from None


def recording_values(args):
    """The keyword arguments of :func:`cmsim.measured.read_record` that the recording
    options of ``args`` give (``fs_hz``, ``speed_rpm``, ``unit``, ``calibration``,
    ``trust_metadata``)."""
    unit = None if args.unit is None else ranged_unit(args.unit)
    return {"fs_hz": args.fs_hz, "speed_rpm": args.speed_rpm, "unit": unit,
            "calibration": args.calibration,
            "trust_metadata": bool(getattr(args, "trust_metadata", False))}


# ---------------------------------------------------------------------- faults
def add_fault_options(p):
    """Add --fault (repeatable) and --faults FILE to the parser ``p``."""
    p.add_argument("--fault", action="append", metavar="TYPE:key=value,...",
                   help="a fault of the catalogue, felt through the dynamics (repeatable), "
                        "e.g. outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4 or "
                        "tooth_crack:gear=1,depth_m=1e-3; types: " + ", ".join(FAULT_NAMES)
                        + "; a rig file's [[faults]] list is applied too")
    p.add_argument("--faults", metavar="FILE.toml",
                   help="faults from a TOML file's [[faults]] list (type = \"...\", fields)")


def faults_of(args, rig):
    """The faults of the rig file's ``[[faults]]``, ``--faults FILE`` and each ``--fault``
    of ``args`` (in that order), each checked against ``rig``; bad input names the option
    that gave it."""
    from cmsim.faults import first_clash, load_faults, parse_fault

    found = []                                    # (where, fault)
    for option, path, rig_file in (("--rig", getattr(args, "rig", None), True),
                                   ("--faults", getattr(args, "faults", None), False)):
        if path:
            loaded = load_file(option, path, partial(load_faults, rig_file=rig_file),
                               "a TOML file with a [[faults]] list")
            found += [(f"{option} {path}: faults[{i}] ({f.name})", f)
                      for i, f in enumerate(loaded)]
    for text in getattr(args, "fault", None) or ():
        try:
            found.append((f"--fault {text}", parse_fault(text)))
        except ParameterError as exc:
            raise CLIError(f"--fault {text}: {' '.join(str(exc).split())} (form: "
                           f"TYPE:key=value,...)", option="--fault") from None
        except TypeError as exc:                  # a required field left out
            missing = re.findall(r"'(\w+)'", str(exc))
            raise CLIError(f"--fault {text}: {', '.join(missing) or 'a parameter'} must be "
                           f"given (form: TYPE:key=value,...)", option="--fault") from None
    for where, fault in found:
        try:
            fault.validate(rig)
        except ParameterError as exc:
            raise CLIError(f"{where}: {' '.join(str(exc).split())}",
                           option=where.split()[0]) from None
    clash = first_clash([f for _, f in found])
    if clash is not None:
        i, j, why = clash
        raise CLIError(f"{found[j][0]} {why} {found[i][0]}; give each fault once",
                       option=found[j][0].split()[0])
    return tuple(f for _, f in found)


# ---------------------------------------------------------------------- losses
def add_losses_option(p):
    """Add --losses to the parser ``p`` (simulate, sweep)."""
    p.add_argument("--losses", action="store_true",
                   help="every loss source in the run: windage, pumping and bearing friction "
                        "torques resist the rotations, the tooth friction follows the "
                        "mixed-lubrication film (paper 000, 004); the run's meta carries the "
                        "breakdown by source and its power balance")


def check_losses_options(args):
    """--losses sets the tooth friction itself: refuse --friction beside it in ``args``."""
    if getattr(args, "losses", False) and getattr(args, "friction", None) is not None:
        raise CLIError("--losses sets the tooth friction from the lubricant film along the "
                       "path; leave out --friction", option="--friction")


def resolved_setup(args):
    """``(rig, op, (table, on-line model))`` of a command at one operating point (modes,
    losses): the rig and operating point of ``args`` and the tooth contact its mesh options
    name, resolved at the operating torque."""
    from cmsim.dynamics.tooth_contact import resolve_mesh

    rig = load_rig(args)
    op = operating_point(args, rig)
    mesh = mesh_argument(args, rig, [op.torque_nm])
    return rig, op, resolve_mesh(rig, mesh, op.torque_nm, progress=False if args.json else None)


def operating_point(args, rig):
    """The OperatingPoint of --speed-rpm, --torque-nm, --radial-load-n in ``args``, with the
    load warnings of :func:`operating_warnings` for ``rig``."""
    op = OperatingPoint(speed_rpm=args.speed_rpm, torque_nm=getattr(args, "torque_nm", 0.0),
                        radial_load_n=getattr(args, "radial_load_n", 0.0))
    operating_warnings(args, rig, op)
    return op
