"""`python -m bumpbake ...` and the `bumpbake` console script: the command line itself."""

from __future__ import annotations

import sys

from bumpbake import _native


def main() -> None:
    """Run the bumpbake command line on ``sys.argv`` and exit with its code."""
    sys.stdout.flush()
    sys.exit(_native.main(["bumpbake", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
