"""Where the TD3 tools these scripts build on live: td3_reach.py (the calibration rungs) and
_students.py sit with the experiment that wrote them; importing this module puts that folder
on sys.path (worker processes started by fork inherit it)."""

from __future__ import annotations

import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[1] / "td3-horizon-exploration-reach"
if str(TOOLS) not in sys.path:
    sys.path.insert(0, str(TOOLS))


def main() -> None:
    print(TOOLS)


if __name__ == "__main__":
    main()
