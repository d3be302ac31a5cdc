"""The scripts run from a shell without `source ./env.sh`: one line saying so, exit 1."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tutorial_atlas_control.cli.environment import run_script

REPO = Path(__file__).resolve().parents[3]
SYSTEM_PYTHON = '/usr/bin/python3'
#: A shell as a new terminal has it before `source ./env.sh`.
BARE_ENV = {'PATH': '/usr/bin:/bin', 'HOME': str(Path.home()), 'LANG': 'C.UTF-8'}


def system_python_lacks_rosbags() -> bool:
    probe = subprocess.run([SYSTEM_PYTHON, '-c', 'import rosbags'], env=BARE_ENV,
                           capture_output=True, check=False)
    return probe.returncode != 0


@pytest.mark.skipif(not Path(SYSTEM_PYTHON).exists() or not system_python_lacks_rosbags(),
                    reason='needs a system python without the virtualenv\'s rosbags')
@pytest.mark.parametrize('script', ['analyze_bag.py', 'replay_bag.py', 'run_offline.py',
                                    'run_demo.py'])
@pytest.mark.parametrize('args', [['--help'], ['some.bag']])
def test_a_script_without_the_environment_says_to_source_env_sh(script: str,
                                                                args: list[str]) -> None:
    result = subprocess.run([SYSTEM_PYTHON, str(REPO / 'scripts' / script), *args],
                            env=BARE_ENV, capture_output=True, text=True, check=False)
    assert result.returncode == 1
    assert result.stdout == ''
    assert result.stderr == (
        f'{script}: error: cannot import rosbags: this shell lacks the project\'s environment; '
        'run `source ./env.sh` in the repository first (after `make setup`)\n')


def test_a_missing_module_of_the_package_itself_keeps_its_traceback() -> None:
    with pytest.raises(ModuleNotFoundError, match='tutorial_atlas_control.cli.no_such'):
        run_script('x.py', 'tutorial_atlas_control.cli.no_such')


def test_the_entry_returns_main_s_status(monkeypatch: pytest.MonkeyPatch) -> None:
    from tutorial_atlas_control.cli import run_offline
    monkeypatch.setattr(run_offline, 'main', lambda: 7)
    assert run_script('run_offline.py', 'tutorial_atlas_control.cli.run_offline') == 7



def test_output_piped_into_head_ends_quietly_with_141(tmp_path: Path) -> None:
    """A script piped into `head`: the reader leaves early; no BrokenPipeError traceback.

    The script writes 1 MB, more than a pipe holds, so its writes fail once `head` is gone.
    """
    (tmp_path / 'chatty.py').write_text(
        'def main() -> int:\n'
        '    for _ in range(1000):\n'
        '        print("x" * 1000)\n'
        '    return 0\n')
    entry = ('import sys; from tutorial_atlas_control.cli.environment import run_script; '
             'sys.exit(run_script("chatty.py", "chatty"))')
    pipeline = subprocess.run(
        ['bash', '-c', f'set -o pipefail; "{sys.executable}" -c \'{entry}\' | head -c 3'],
        capture_output=True, text=True, check=False, timeout=120,
        env={**os.environ, 'PYTHONPATH': f'{tmp_path}:{REPO / "src"}'})
    assert pipeline.stdout == 'xxx'
    assert pipeline.stderr == ''
    assert pipeline.returncode == 141
