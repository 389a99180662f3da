"""``cmsim import``: a folder of recordings documented as ``metadata.json`` (what the files
state, the rest from the options), so compare, calibrate, spectrum and evaluate read it."""

from __future__ import annotations

from pathlib import Path

from cmsim.cli.contract import CLIError
from cmsim.cli.options import add_recording_options, recording_values
from cmsim.errors import ParameterError


def register(sub):
    """Add the ``import`` parser."""
    p = sub.add_parser("import", help="write metadata.json for a folder of recordings",
                       description="Read every recording of DIR (.npz, .csv, .wav, .mat, "
                                   ".uff/.unv, .tdms) and write the metadata.json cmsim "
                                   "reads: channel names, sample rate, units and speed as "
                                   "the files state them, the rest from --fs-hz, "
                                   "--speed-rpm, --unit, --calibration and --channel (a file "
                                   "and an option that disagree are refused). Geometry and "
                                   "the answer key are not in any file: add them by hand.")
    p.add_argument("dir", type=Path, metavar="DIR", help="folder of recordings")
    p.add_argument("--out", type=Path, metavar="FILE.json",
                   help="metadata file to write (default DIR/metadata.json, where compare "
                        "and the others look for it)")
    p.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    p.add_argument("--channel", nargs="+", metavar="NAME",
                   help="names of a file's unnamed channels (a WAV's, in order), or the "
                        "channels to document of files that name theirs")
    add_recording_options(p)
    p.set_defaults(func=run, text=text)


def run(args):
    """Read the folder, write its metadata."""
    from cmsim.measured.importing import folder_metadata, write_folder_metadata

    out = args.out or args.dir / "metadata.json"
    if out.exists() and not args.force:
        raise CLIError(f"--out {out}: exists; give --force to overwrite it", option="--out")
    values = recording_values(args)
    try:
        meta, undocumented = folder_metadata(args.dir, channels=args.channel, **values)
    except ParameterError as exc:
        if exc.param not in ("record", "dataset"):
            raise
        raise CLIError(f"DIR {' '.join(str(exc).split())}", option="DIR") from None
    write_folder_metadata(out, meta, force=True)
    for what in undocumented:
        args.warn(f"{what} undocumented (give it with an option, or edit {out.name})")
    recs = meta["recordings"]
    return {"metadata": str(out), "dir": str(args.dir), "n_recordings": len(recs),
            "fs_hz": meta["fs_hz"], "channels": sorted(meta["channels"]),
            "units": {c: s["unit"] for c, s in meta["sensors"].items()},
            "recordings": [{k: r.get(k) for k in ("file", "n_samples", "fs_hz",
                                                  "shaft_speed_rpm", "channels")}
                           for r in recs],
            "undocumented": list(undocumented)}


def text(res):
    """One line per recording and where the metadata went."""
    lines = [f"{r['file']}: {r['n_samples']} samples"
             + (f" at {r['fs_hz']:g} Hz" if r["fs_hz"] else ", rate undocumented")
             + (f", {r['shaft_speed_rpm']:g} rpm" if r["shaft_speed_rpm"] else "")
             + f"; channels {', '.join(r['channels'])}" for r in res["recordings"]]
    lines.append(f"wrote {res['metadata']} ({res['n_recordings']} recordings; add geometry "
                 f"and the answer key by hand)")
    return "\n".join(lines)
