"""``cmsim spectrum``: labelled amplitude, envelope or order spectrum of one signal of a run."""

from __future__ import annotations

from pathlib import Path

from cmsim.cli.contract import CLIError, load_file, ranged
from cmsim.cli.options import add_recording_options, recording_values
from cmsim.errors import ParameterError
from cmsim.cli.output import inferred_lines, save_figure, warn_inferred
from cmsim.rig import Range, Rig


def register(sub):
    """Add the ``spectrum`` parser."""
    p = sub.add_parser("spectrum", help="labelled spectrum of one signal of a record",
                       description="Amplitude, envelope or order spectrum of a signal of any "
                                   "record cmsim writes or reads (run, dataset record, "
                                   "measured recording with its metadata.json), with its "
                                   "largest peaks named k·GMF ± m·BPF ± n·fr from the "
                                   "record's own rig and operating point.")
    p.add_argument("record", type=Path, metavar="RECORD",
                   help="a run (cmsim simulate, sweep), a dataset record (cmsim dataset) or "
                        "a measured recording (.npz/.csv/.wav/.mat/.uff/.tdms; what the file "
                        "does not state from metadata.json beside it, else from the options "
                        "below); a relative path is also looked up under $CMSIM_DATA")
    p.add_argument("--rig", metavar="FILE.toml",
                   help="model rig of a measured recording (default: built from its "
                        "metadata.json geometry)")
    add_recording_options(p)
    p.add_argument("--channel", metavar="NAME",
                   help="channel (signal) name (default: F_1b1_loa of a simulated run, the "
                        "first channel of a dataset record, the compared channel of a "
                        "measured recording)")
    p.add_argument("--signal", dest="signal_alias", metavar="NAME",
                   help="the old name of --channel (deprecated)")
    p.add_argument("--kind", default="amplitude", choices=("amplitude", "envelope", "order"),
                   help="spectrum kind")
    p.add_argument("--band-hz", type=ranged(Range(0.0, 1.0e7, unit="Hz")), nargs=2,
                   metavar=("LO", "HI"),
                   help="demodulation band for --kind envelope, Hz (default: kurtogram's)")
    p.add_argument("--max-hz", type=ranged(Range(0.0, 1.0e7, lo_open=True, unit="Hz")),
                   metavar="F", help="list peaks up to F Hz")
    p.add_argument("--resolution-hz", type=ranged(Range(0.0, 1.0e6, lo_open=True, unit="Hz")),
                   metavar="R", help="required bin spacing, Hz (error if the record is too short)")
    p.add_argument("--bearing", help="bearing for the BPF family (default: from the signal)")
    p.add_argument("--top", type=ranged(Range(1, 1000, integer=True)), default=20,
                   help="number of largest peaks listed")
    p.add_argument("--threshold-db", type=ranged(Range(0.0, 200.0, unit="dB")), default=15.0,
                   help="least peak height above the noise floor, dB")
    p.add_argument("--plot", type=Path, metavar="OUT.png", help="write the spectrum figure")
    p.set_defaults(func=run, text=text)


def run(args):
    """The spectrum's labelled peaks (and its figure)."""
    from cmsim.spectra.run_spectrum import run_spectrum

    if args.signal_alias is not None:
        if args.channel is not None:
            raise CLIError("--signal is the old name of --channel: give one of them",
                           option="--signal")
        args.warn("--signal is deprecated: it is now --channel, as in compare and calibrate")
        args.channel = args.signal_alias
    try:
        run_, default_signal = _read(args)
        signal = args.channel or default_signal or "F_1b1_loa"
        spec = run_spectrum(run_, signal, args.kind, band_hz=args.band_hz,
                            max_hz=args.max_hz, resolution_hz=args.resolution_hz,
                            bearing=args.bearing, max_peaks=args.top,
                            threshold_db=args.threshold_db)
    except ParameterError as exc:
        # the channel named by the old option: the message names the option as typed
        if args.signal_alias is None or exc.param not in ("signal", "channel", "--channel"):
            raise
        raise CLIError(f"--signal {args.signal_alias}: {' '.join(str(exc).split())}",
                       option="--signal") from None
    out = {"run": str(args.record), "signal": spec.signal, "kind": spec.kind, "unit": spec.unit,
           "resolution_hz": spec.resolution_hz, "bearing": spec.bearing,
           "families": spec.families, "band_hz": list(spec.band_hz) if spec.band_hz else None,
           "max_hz": spec.max_hz, "n_peaks": len(spec.peaks), "peaks": spec.peak_records(),
           "plot": None, "inferred": dict(run_.meta.get("inferred") or {}), **spec.extra}
    warn_inferred(args, out["inferred"])
    if args.plot:
        from cmsim.spectra.plots import plot_spectrum
        fam = spec.families
        fig = plot_spectrum(spec.freq_hz, spec.amplitude, spec.peaks, fam,
                            amplitude_unit=spec.unit, max_freq=spec.max_hz,
                            max_harmonic=max(1, int(spec.max_hz // fam.get("GMF", spec.max_hz))),
                            title=f"{spec.signal}: {spec.kind} spectrum "
                                  f"({spec.resolution_hz:.3g} Hz resolution)")
        save_figure(fig, args.plot)
        out["plot"] = str(args.plot)
    return out


#: Parameters of :func:`cmsim.measured.read_run` whose errors name their own option.
_RECORDING_PARAMS = ("record", "rig", "fs_hz", "speed_rpm", "unit", "calibration", "--channel")


def _read(args):
    """The record of ``args.record`` as a run (:func:`cmsim.measured.read_run`, with --rig and
    the recording options): a measured recording's error names the file itself
    (``RECORD ...``) or the option; a cmsim file that does not load is named here."""
    from cmsim.measured import read_run

    path = args.record
    rig = load_file("--rig", args.rig, Rig.load, "a rig TOML file") if args.rig else None
    try:
        return read_run(path, rig=rig, channel=args.channel, **recording_values(args))
    except ParameterError as exc:
        if exc.param in _RECORDING_PARAMS:
            raise
        return load_file("RECORD", path, _raise(exc), _WHAT)
    except Exception as exc:  # noqa: BLE001 - reported by load_file as one line
        return load_file("RECORD", path, _raise(exc), _WHAT)


_WHAT = "a record cmsim wrote (simulate, sweep, dataset) nor a measured recording"


def _raise(exc):
    def loader(path):
        raise exc
    return loader


def text(res):
    """The peaks as a table."""
    order = res["kind"] == "order"
    fr = res["families"].get("fr") or 1.0
    families = (", ".join(f"{k} {v / fr:.3f}" for k, v in res["families"].items()) + " orders"
                if order else ", ".join(f"{k} {v:.3f} Hz" for k, v in res["families"].items()))
    named = (f"families of bearing {res['bearing']}: " if res["bearing"] is not None
             else "bearings undocumented, peaks named by the gears and shafts only: "
             if "GMF" in res["families"]
             else "no geometry, peaks named by the shaft rate only: ")
    lines = [f"{res['kind']} spectrum of {res['signal']} [{res['unit']}], resolution "
             + (f"{res['resolution_hz'] / fr:.4g} orders (angle from the "
                f"{res.get('angle_from', 'nominal speed')})" if order
                else f"{res['resolution_hz']:.4g} Hz")
             + ", " + named + families]
    lines += inferred_lines(res.get("inferred"))
    if res["band_hz"]:
        lines.append(f"demodulation band {res['band_hz'][0]:.0f}-{res['band_hz'][1]:.0f} Hz")
    column = "order" if order else "frequency_hz"
    lines.append(f"{column:>13}  {'amplitude':>11}  {'dB re carrier':>13}  label")
    for p in res["peaks"]:
        db = "" if p["db_re_carrier"] is None else f"{p['db_re_carrier']:.1f}"
        lines.append(f"{p[column]:13.2f}  {p['amplitude']:11.4g}  {db:>13}  "
                     f"{p['label']}")
    if res["plot"]:
        lines.append(f"wrote {res['plot']}")
    return "\n".join(lines)
