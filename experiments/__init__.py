"""The absl binaries of pushjax (``python -m experiments.<name>``): flags -> validation of their combinations -> one
library call (the logic lives in ``pushjax``).

Each starts with `run(main)` rather than ``app.run(main)``: every usage error, whether absl rejects a flag (a bad
value, a failed validator, an unknown or missing flag), ``main`` raises ``app.UsageError`` (a bad combination of
flags, a file that cannot be read) or meets a push file it cannot use (``pushjax.mit.PushFileError``), is then one
line on stderr,

    error: <flag or file>: <what was expected>

and the exit status `USAGE_ERROR_STATUS` (2), instead of absl's help text (dozens of lines) above the message.
"""

import re
import sys
from collections.abc import Mapping
from typing import NoReturn

from absl import app, flags

from pushjax import compilation_cache, logs
from pushjax.mit.files import PushFileError
from pushjax.paper import paths
from pushjax.sim import testbed

USAGE_ERROR_STATUS = 2
"""The exit status of a usage error (a bad flag or input file), as for other command-line tools."""

_FLAG = r"--?[\w.-]+"


def usage_error_line(message: str) -> str:
    """``error: <message>`` on one line (the message's line breaks and runs of spaces become one space)."""
    return f"error: {' '.join(str(message).split())}"


def exit_usage_error(message: str) -> NoReturn:
    """Prints `usage_error_line` of `message` on stderr and exits with `USAGE_ERROR_STATUS`."""
    sys.stdout.flush()
    print(usage_error_line(message), file=sys.stderr, flush=True)
    sys.exit(USAGE_ERROR_STATUS)


def flag_error_message(error: Exception) -> str:
    """absl's message for a flag it rejects, as ``<flag>: <what was expected>`` (the first problem only)."""
    if isinstance(error, flags.UnrecognizedFlagError):
        suggestions = re.search(r"Did you mean: (.*?) \?$", str(error))
        hint = f"; did you mean --{', --'.join(suggestions[1].split(', '))}?" if suggestions else ""
        return f"--{error.flagname}: unknown flag{hint} (--helpshort lists the flags)"
    # Several failed validators come one per line, each starting with "flag " or "flags ".
    text = " ".join(re.split(r"\n(?=flags? )", str(error))[0].split())
    for pattern, replacement in (
            (rf"flag ({_FLAG})=None: Flag {_FLAG} must have a value other than None\.", r"\1: expected a value (the "
                                                                                         "flag is required)"),
            (rf"flags .*?: ({_FLAG}: .*)", r"\1"),  # a validator of several flags whose message names its flag
            (rf"flag ({_FLAG}=.*)", r"\1"),
            (rf"Missing value for flag ({_FLAG})", r"\1: expected a value"),
            (rf"({_FLAG})=.* does not take an argument", r"\1: takes no value (a boolean flag)")):
        match = re.fullmatch(pattern, text)
        if match:
            return match.expand(replacement)
    return text


def parse_flags_or_exit(argv: list[str]) -> list[str]:
    """``FLAGS(argv)``; a flag error exits with status 2 and one line ``error: <flag>: <what was expected>``."""
    try:
        return flags.FLAGS(argv)
    except (flags.Error, ValueError) as error:  # absl raises a ValueError for a value given to --noflag
        exit_usage_error(flag_error_message(error))


def run(main) -> None:
    """``app.run(main)`` with one-line usage errors: a flag absl rejects (`parse_flags_or_exit`), an
    ``app.UsageError`` raised by `main` and a push file it cannot use (``pushjax.mit.PushFileError``, which names the
    file and the field) print ``error: <message>`` on stderr, without absl's help text or a traceback, and exit with
    `USAGE_ERROR_STATUS`. Before `main`, JAX's persistent compilation cache is enabled
    (`pushjax.compilation_cache`: ``~/.cache/pushjax/xla``; ``PUSHJAX_COMPILATION_CACHE=off`` compiles afresh), so a
    second run of a command loads the programs the first compiled, and the known log noise is dropped
    (`pushjax.logs`)."""

    def main_with_one_line_usage_errors(argv):
        logs.quiet_known_noise()
        compilation_cache.enable()
        try:
            return main(argv)
        except (app.UsageError, PushFileError) as error:
            exit_usage_error(str(error))

    app.run(main_with_one_line_usage_errors, flags_parser=parse_flags_or_exit)


def config_error(error: ValueError, flag_names: Mapping[str, str] | None = None) -> app.UsageError:
    """A study config's ValueError, ``<field>: <what was expected>``, as the usage error of the flag that sets the
    field, ``--<flag>: <what was expected>`` (`flag_names`: {field: flag name} where the two differ)."""
    field, colon, expected = " ".join(str(error).split()).partition(":")
    return app.UsageError(f"--{(flag_names or {}).get(field, field)}{colon}{expected}")


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
