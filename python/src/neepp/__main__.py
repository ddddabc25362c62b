"""`neepp` (the command installed with the package, or python -m neepp): runs the CLI built with it."""
import os
import sys
from pathlib import Path


def main() -> None:
    exe = Path(__file__).resolve().parent / "bin" / "neepp"
    if not exe.exists():
        sys.exit(f"neepp: the command-line tool was not installed with this package ({exe} is missing)")
    os.execv(str(exe), [str(exe)] + sys.argv[1:])


if __name__ == "__main__":
    main()
