#!/usr/bin/env python3
"""docs/extending.md quotes each worked example whole, in a block opened by ```cpp docs/extending/NAME.cpp:
fails (exit 1) when a quote differs from the file that tests/extending builds, or an example is not quoted."""
import re
import sys
from pathlib import Path

root = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parents[2])
page = (root / "docs" / "extending.md").read_text()
quoted = {m.group(1): m.group(2) for m in re.finditer(r"^```cpp (docs/extending/\S+)\n(.*?)^```$", page, re.M | re.S)}
problems = []
for src in sorted((root / "docs" / "extending").glob("*.cpp")) + sorted((root / "docs" / "extending").glob("*.h")):
    rel = src.relative_to(root).as_posix()
    if rel not in quoted:
        problems.append(f"{rel} is not quoted in docs/extending.md")
    elif quoted[rel] != src.read_text():
        problems.append(f"docs/extending.md's quote of {rel} differs from the file (copy the file into the page)")
for rel in quoted:
    if not (root / rel).exists():
        problems.append(f"docs/extending.md quotes {rel}, which does not exist")
for p in problems:
    print(p)
print(f"{len(quoted)} examples quoted, {len(problems)} problems")
sys.exit(1 if problems else 0)
