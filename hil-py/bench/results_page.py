"""Results pages for the benchmark scripts: the report a script printed,
kept as a Markdown file (e.g. docs/results/python-linucb-bench.md) that
names the command which wrote it, so a README cites the page instead of
hand-typed figures.

The format is the one `hil_experiments::results_page::ResultsPage` writes
for the `hil` commands (`to_markdown` there); keep the two identical.
"""

from __future__ import annotations

import os
import shlex
import sys
from pathlib import Path
from typing import Sequence

# The workspace root: commands on a page are written relative to it.
ROOT = Path(__file__).resolve().parents[2]


def command_line(script: str, argv: Sequence[str]) -> str:
    """`python SCRIPT ARGS...`, the script's path relative to the workspace
    root and each argument shell-quoted, as one reruns it from the root."""
    rel = os.path.relpath(Path(script).resolve(), ROOT)
    return shlex.join(["python", rel, *argv])


def to_markdown(title: str, command: str, report: str) -> str:
    """The page: a marker that the file is generated, the heading, the
    command, and the report verbatim in a text block."""
    newline = "" if report.endswith("\n") else "\n"
    return (f"<!-- Written by `{command}`: do not edit by hand, rerun the command. -->\n"
            f"# {title}\n\n"
            "Written by the command below; rerun it to refresh this page.\n\n"
            f"```sh\n{command}\n```\n\n"
            f"```text\n{report}{newline}```\n")


def write(path: str | os.PathLike, title: str, command: str, report: str) -> None:
    """Writes the page to `path`, creating its folder if needed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(to_markdown(title, command, report), encoding="utf-8")


def emit(report: str, write_doc: str | None, title: str, script: str,
         argv: Sequence[str] | None) -> None:
    """Prints `report` and, with `write_doc`, keeps it as a page naming the
    command (`argv`, or the process's own arguments when None), as the
    CLI's `emit_report` does for `--write-doc`."""
    print(report, end="")
    if write_doc:
        args = sys.argv[1:] if argv is None else argv
        write(write_doc, title, command_line(script, args), report)
        print(f"wrote {write_doc}", file=sys.stderr)
