"""Running the package's scripts as a user does after `source ./env.sh`."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

SCRIPTS = Path(__file__).resolve().parents[2] / 'scripts'
#: Wall-clock guard (s) against a hang; the offline searches and sweeps take a minute or so.
SCRIPT_TIMEOUT_S = 600.0


def run_script(name: str, *args: str,
               timeout_s: float = SCRIPT_TIMEOUT_S) -> subprocess.CompletedProcess[str]:
    """scripts/`name` with `args`: exit code, stdout and stderr captured as text."""
    return subprocess.run([sys.executable, str(SCRIPTS / name), *args], capture_output=True,
                          text=True, timeout=timeout_s, check=False)
