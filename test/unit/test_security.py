"""Security defaults: localhost-only ROS, and no unsafe YAML loading anywhere in the tree."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
#: yaml.load without an explicit safe loader, or the loaders that construct arbitrary objects.
UNSAFE_YAML = re.compile(r'yaml\.(unsafe_load|full_load|load_all|load)\s*\((?![^)]*SafeLoader)')
THIS_FILE = Path(__file__).resolve()


def python_sources() -> list[Path]:
    files = [p for p in REPO.rglob('*.py') if '.git' not in p.parts]
    scripts = [p for p in (REPO / 'scripts').iterdir() if p.is_file()]
    return sorted(set(files + scripts) - {THIS_FILE})


def test_no_unsafe_yaml_loading_in_the_tree() -> None:
    offenders = []
    for path in python_sources():
        for number, line in enumerate(path.read_text(errors='replace').splitlines(), 1):
            if UNSAFE_YAML.search(line):
                offenders.append(f'{path.relative_to(REPO)}:{number}: {line.strip()}')
    assert not offenders, 'use yaml.safe_load:\n' + '\n'.join(offenders)


def test_the_pattern_catches_unsafe_calls() -> None:
    assert UNSAFE_YAML.search('doc = yaml.load(stream)')
    assert UNSAFE_YAML.search('yaml.unsafe_load(text)')
    assert not UNSAFE_YAML.search('yaml.safe_load(text)')
    assert not UNSAFE_YAML.search('yaml.load(text, Loader=yaml.SafeLoader)')


def ros_network_after_sourcing(env: dict[str, str]) -> list[str]:
    """ROS_HOSTNAME and ROS_MASTER_URI as `source ./env.sh` leaves them, given `env`."""
    result = subprocess.run(
        ['bash', '-c', 'source ./env.sh >/dev/null && echo "$ROS_HOSTNAME $ROS_MASTER_URI"'],
        cwd=REPO, env=env, capture_output=True, text=True, check=False)
    # A failing env.sh is a defect (or a clone not set up: make setup), never a skip.
    assert result.returncode == 0, f'source ./env.sh failed: {result.stderr}'
    return result.stdout.split()


def test_env_sh_binds_ros_to_localhost_by_default() -> None:
    env = {k: v for k, v in os.environ.items()
           if k not in ('ROS_HOSTNAME', 'ROS_IP', 'ROS_MASTER_URI')}
    assert ros_network_after_sourcing(env) == ['localhost', 'http://localhost:11311']


def test_env_sh_keeps_a_deliberate_network_setting() -> None:
    env = dict(os.environ, ROS_HOSTNAME='robot.lan', ROS_MASTER_URI='http://robot.lan:11311')
    assert ros_network_after_sourcing(env) == ['robot.lan', 'http://robot.lan:11311']
