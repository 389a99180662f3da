"""mkdocs hook: the pages that are generated from the code at build time.

* ``reference/cli.md`` — every ``cmsim`` command, its usage and a table of its options, read
  from the argparse parser (:func:`cmsim.cli.app.build_parser`): a new command or option
  appears here without anyone writing it down.
* ``reference/api/<unit>.md`` — one page per part of the package (``cmsim.dynamics``, ...),
  one ``::: module`` block (mkdocstrings, numpydoc style) per public module in it; the pages
  are put into the navigation under "API reference" in the order of the package's layers.

Nothing is written into ``docs/``: the pages exist only in the build.
"""

from __future__ import annotations

import argparse
import html
import pkgutil
import textwrap

from mkdocs.structure.files import File

#: Parts of the package in the order of their layers (DESIGN.md, Layout), with the title of
#: their API page. ``cmsim`` holds the top-level modules (errors, run, frequencies, ...).
#: A part missing here is listed after these, so a new one is never left out.
UNITS = {
    "cmsim": "Top level: errors, runs, frequencies, sensors",
    "cmsim.rig": "Rig parameters",
    "cmsim.bearings": "Bearings",
    "cmsim.mesh_stiffness": "Mesh stiffness",
    "cmsim.faults": "Faults",
    "cmsim.losses": "Power losses",
    "cmsim.dynamics": "Dynamics",
    "cmsim.spectra": "Spectra",
    "cmsim.measured": "Measured records",
    "cmsim.features": "Features",
    "cmsim.machine": "Machine calibration",
    "cmsim.datasets": "Datasets",
    "cmsim.studies": "Paper studies",
    "cmsim.diagnostics": "Diagnostics",
    "cmsim.discrepancy": "Discrepancy",
}
#: Parts documented elsewhere: the command line has its generated page.
SKIP = {"cmsim.cli"}
API_SECTION = "API reference"
CLI_PAGE = "reference/cli.md"
#: {unit: modules} of this build (on_config finds them, on_files writes their pages).
_API_UNITS = {}


def _public_modules():
    """{unit: [module, ...]}: every module of cmsim whose name has no leading underscore."""
    import cmsim

    units = {name: [] for name in UNITS}
    units["cmsim"].append("cmsim")
    for info in pkgutil.walk_packages(cmsim.__path__, "cmsim."):
        parts = info.name.split(".")
        if any(p.startswith("_") for p in parts) or ".".join(parts[:2]) in SKIP:
            continue
        unit = "cmsim" if len(parts) == 2 and not info.ispkg else ".".join(parts[:2])
        units.setdefault(unit, []).append(info.name)
    return {u: sorted(set(m), key=lambda n: (n != u, n)) for u, m in units.items() if m}


def _api_path(unit):
    return f"reference/api/{unit.replace('.', '_')}.md"


def _api_page(unit, modules):
    title = UNITS.get(unit, unit)
    lines = [f"# {title} (`{unit}`)", "",
             "Generated from the docstrings (numpydoc) at build time.", ""]
    for module in modules:
        lines += [f"::: {module}", ""]
    return "\n".join(lines)


def _cell(text):
    """Text safe inside a markdown table cell."""
    text = " ".join(str(text).split())
    return html.escape(text, quote=False).replace("|", "\\|").replace("*", "\\*")


def _action_row(parser, action):
    formatter = parser._get_formatter()
    if action.option_strings:
        name = ", ".join(action.option_strings)
        if action.nargs != 0:
            name += " " + formatter._format_args(action, action.dest.upper())
    else:
        name = formatter._format_args(action, action.dest)
    help_text = formatter._expand_help(action) if action.help else ""
    if action.choices and not isinstance(action, argparse._SubParsersAction):
        help_text += f" (one of: {', '.join(map(str, action.choices))})"
    default = action.default
    shown = "" if default in (None, False, argparse.SUPPRESS) or action.nargs == 0 \
        else f"`{default}`"
    return f"| `{_cell(name)}` | {_cell(help_text)} | {shown} |"


def cli_reference():
    """The markdown of the command-line reference, from :func:`cmsim.cli.app.build_parser`."""
    from cmsim.cli.app import build_parser
    from cmsim.cli.contract import subparsers

    parser = build_parser()
    lines = ["# Command-line reference", "",
             "Generated from the argparse parser (`cmsim.cli.app.build_parser`) when the "
             "site is built; `cmsim COMMAND --help` prints the same. Every command takes "
             "`--json` (one JSON object on stdout, also on errors: "
             '`{"error", "status", "option"}`); exit status 0 success, 1 internal error, '
             "2 bad input, 3 diverged integration, 130 interrupted, 141 stdout closed "
             "early (`cmsim ... | head`; quietly, as a Unix filter). Progress of long steps "
             "(a first numba compile, an FE gear-body build) goes to stderr "
             "(`CMSIM_PROGRESS=0` silences it).", "",
             "```text", parser.format_usage().strip(), "```", ""]
    for name, sub in subparsers(parser).items():
        lines += [f"## `cmsim {name}`", ""]
        if sub.description:
            lines += [textwrap.fill(" ".join(sub.description.split()), 92), ""]
        lines += ["```text", sub.format_usage().strip(), "```", "",
                  "| argument | meaning | default |", "| --- | --- | --- |"]
        lines += [_action_row(sub, a) for a in sub._actions
                  if not isinstance(a, argparse._HelpAction)]
        lines.append("")
    return "\n".join(lines)


def on_config(config):
    """Put one navigation entry per API page under the "API reference" section."""
    units = _public_modules()
    pages = [{UNITS.get(u, u): _api_path(u)} for u in units]
    for i, item in enumerate(config["nav"] or []):
        if isinstance(item, dict) and API_SECTION in item:
            config["nav"][i] = {API_SECTION: pages}
            break
    _API_UNITS.clear()
    _API_UNITS.update(units)
    return config


def on_files(files, config):
    """Add the generated pages to the build."""
    files.append(File.generated(config, CLI_PAGE, content=cli_reference()))
    for unit, modules in _API_UNITS.items():
        files.append(File.generated(config, _api_path(unit), content=_api_page(unit, modules)))
    return files
