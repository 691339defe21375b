"""The absl binaries of pushjax (``python -m experiments.<name>``): a few lines each, flags -> library call.

Each starts with `run(main)` rather than ``app.run(main)``: a flag absl rejects (a bad value, a failed
validator, an unknown or missing flag) is then one line naming the flag and what it expects, like the usage
errors ``main`` raises, instead of absl's two lines ending in a hint.
"""

import sys

from absl import app, flags

from pushjax.paper import paths
from pushjax.sim import testbed


def parse_flags_or_exit(argv: list[str]) -> list[str]:
    """``FLAGS(argv)``; a flag error exits with status 1 and one line naming the flag on stderr."""
    try:
        return flags.FLAGS(argv)
    except flags.Error as error:
        sys.exit(f"FATAL Flags parsing error: {' '.join(str(error).split())} (--helpshort lists the flags)")


def run(main) -> None:
    """``app.run(main)`` with one-line flag errors (`parse_flags_or_exit`)."""
    app.run(main, flags_parser=parse_flags_or_exit)


def require_writable_folder(flag_name: str) -> None:
    """Makes flag `flag_name` reject a value that is not a folder files can be written in, or can be created."""

    def check(folder: str | None) -> bool:
        if folder is None:  # the flag is missing, which its own (required) check reports
            return True
        try:
            paths.check_writable_folder(folder)
        except ValueError as error:
            raise flags.ValidationError(str(error)) from None
        return True

    flags.register_validator(flag_name, check)


def define_testbed_flag() -> flags.FlagHolder:
    """Defines ``--testbed`` (``pushjax.sim.testbed.PROFILES``, default ``realistic``) for a binary that records or
    builds data without the experiments' shared flags (``pushjax.paper.cli`` defines it for those)."""
    return flags.DEFINE_enum("testbed", testbed.DEFAULT_PROFILE, list(testbed.PROFILES), testbed.FLAG_HELP)


def testbed_from_flags(profile: str, overrides: str) -> testbed.Testbed:
    """The testbed profile of ``--testbed`` with ``--testbed_overrides``; a bad override is a usage error naming
    ``--testbed_overrides``."""
    try:
        return testbed.from_flags(profile, overrides)
    except ValueError as error:
        raise app.UsageError(f"--testbed_overrides: {error}") from None
