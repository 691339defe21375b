"""Whether two work directories hold the same results: a refactoring's before / after check.

    .venv/bin/python scripts/same_results.py OLD_WORKDIR NEW_WORKDIR [--ignore=data_dir,...]

Compares every ``results.json`` and every model record (``models/*.json``) under OLD_WORKDIR with the file of the same
path under NEW_WORKDIR, field by field: numbers, curves, verdicts and configs must be equal; what says when, where
and from which code a run was made is left out (`VOLATILE`: wall times, steps per second, start times, the commit,
provenance and its diff) and so are the fields named by ``--ignore``. Prints one line per file (``same`` or the first
differences, ``path/to/field: old != new``) and exits 1 if any file differs or is missing under NEW_WORKDIR.

How a refactoring that must not change behaviour is checked: run the smoke commands from a checkout of the commit
before it (``git worktree add /tmp/before <commit>``) and from the working tree into two folders, then compare them.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterator
from pathlib import Path

VOLATILE = frozenset({"train_seconds", "eval_seconds", "steps_per_second", "started", "commit", "provenance",
                      "source_diff", "wall_s", "invocations", "model_seconds", "seconds"})
"""Fields that say when, where or from which code a run was made, not what it found."""


def differences(old, new, ignore: frozenset[str] = frozenset(), path: str = "") -> Iterator[str]:
    """``field: old != new`` for every difference of two JSON values, the fields in `VOLATILE` and `ignore` left out."""
    skipped = VOLATILE | ignore
    if isinstance(old, dict) and isinstance(new, dict):
        for key in sorted((set(old) | set(new)) - skipped):
            if key not in old or key not in new:
                yield f"{path}/{key}: only in {'new' if key not in old else 'old'}"
            else:
                yield from differences(old[key], new[key], ignore, f"{path}/{key}")
    elif isinstance(old, list) and isinstance(new, list):
        if len(old) != len(new):
            yield f"{path}: {len(old)} items != {len(new)}"
        else:
            for index, (old_item, new_item) in enumerate(zip(old, new)):
                yield from differences(old_item, new_item, ignore, f"{path}[{index}]")
    elif old != new or type(old) is not type(new):
        yield f"{path or '/'}: {json.dumps(old)[:60]} != {json.dumps(new)[:60]}"


def compared_files(workdir: Path) -> list[Path]:
    """The files `main` compares, relative to `workdir`: every results.json and model record below it."""
    return sorted({path.relative_to(workdir) for pattern in ("**/results.json", "**/models/*.json")
                   for path in workdir.glob(pattern)})


def _usage_error(message: str) -> int:
    print(f"error: {message}", file=sys.stderr)
    return 2


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("old", type=Path, help="the work directory made before")
    parser.add_argument("new", type=Path, help="the work directory made after")
    parser.add_argument("--ignore", default="", help="more fields to leave out, comma-separated (e.g. data_dir)")
    arguments = parser.parse_args(argv)
    for name in ("old", "new"):
        if not getattr(arguments, name).is_dir():
            return _usage_error(f"{name}: {getattr(arguments, name)} is not a directory")
    files = compared_files(arguments.old)
    if not files:
        return _usage_error(f"old: {arguments.old} holds no results.json and no models/*.json")
    ignore = frozenset(filter(None, arguments.ignore.split(",")))
    differing = 0
    for relative in files:
        if not (arguments.new / relative).is_file():
            print(f"{relative}: missing in {arguments.new}")
            differing += 1
            continue
        found = list(differences(json.loads((arguments.old / relative).read_text()),
                                 json.loads((arguments.new / relative).read_text()), ignore))
        print(f"{relative}: " + ("same" if not found else "; ".join(found[:3]) + (
            f" (and {len(found) - 3} more)" if len(found) > 3 else "")))
        differing += bool(found)
    print(f"{len(files) - differing} of {len(files)} files the same")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())
