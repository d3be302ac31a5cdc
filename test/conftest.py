"""Makes src/ and the test helpers (test/, test/unit/) importable when pytest runs from a clone."""

import sys
from pathlib import Path

_TEST_DIR = Path(__file__).resolve().parent
for _path in (_TEST_DIR.parent / 'src', _TEST_DIR, _TEST_DIR / 'unit'):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))
