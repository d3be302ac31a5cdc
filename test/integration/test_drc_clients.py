"""DRC-era Python clients from env.sh's shell: the modules DRCSim's tutorials imported, and a
`#!/usr/bin/env python` client (drc_client.py) run with rosrun and directly.

Each shell starts from a bare environment (the system's PATH, an empty HOME, no ROS
variables), so what works here works because `make setup` and env.sh set it up: `python` is
the virtualenv's (Debian's python3) inside env.sh's shell only, tf.transformations,
tf_conversions.posemath, PyKDL, actionlib and roslib import, and roslib.load_manifest finds
the client's own package whether it is a catkin package (package.xml) or a DRC-era rosbuild
one (manifest.xml, which walks its dependencies).

Needs `make setup`; about 10 s of wall time, no master.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

if shutil.which('rosrun') is None or 'TAC_HOME' not in os.environ:
    pytest.skip('needs the project environment (source env.sh)', allow_module_level=True)

REPO = Path(__file__).resolve().parents[2]
CLIENT = Path(__file__).resolve().parent / 'drc_client.py'
PROBE_PACKAGE = 'drc_client_probe'
#: The modules DRC-era clients import (DRCSim's walk.py, demo.py, joint_animation.py, ...).
DRC_ERA_MODULES = ('roslib', 'rospy', 'tf', 'tf.transformations', 'tf_conversions',
                   'tf_conversions.posemath', 'PyKDL', 'actionlib', 'actionlib_msgs.msg',
                   'tf2_ros', 'tf2_geometry_msgs', 'tf2_kdl', 'angles', 'trajectory_msgs.msg',
                   'atlas_msgs.msg', 'osrf_msgs.msg')
SHELL_TIMEOUT_S = 120.0
CATKIN_PACKAGE_XML = f"""<?xml version="1.0"?>
<package format="2">
  <name>{PROBE_PACKAGE}</name>
  <version>0.0.0</version>
  <description>A DRC-era client, as a catkin package.</description>
  <maintainer email="probe@example.com">probe</maintainer>
  <license>Apache-2.0</license>
  <buildtool_depend>catkin</buildtool_depend>
  <exec_depend>rospy</exec_depend>
  <exec_depend>tf</exec_depend>
</package>
"""
ROSBUILD_MANIFEST_XML = """<package>
  <description brief="probe">A DRC-era client, as roscreate-pkg made it.</description>
  <author>probe</author>
  <license>BSD</license>
  <depend package="rospy"/>
  <depend package="trajectory_msgs"/>
  <depend package="std_msgs"/>
  <depend package="tf"/>
  <depend package="tf_conversions"/>
  <depend package="actionlib"/>
</package>
"""
#: What drc_client.py prints, line by line, before the line naming its interpreter.
CLIENT_OUTPUT = [
    'quaternion_from_euler(0, 0, pi/2): 0.000000 0.000000 0.707107 0.707107',
    'euler_from_quaternion: 0.000000 -0.000000 1.570796',
    'posemath foot in world: 1.000000 2.250000 0.000000',
    'actionlib: SimpleActionClient rospy: /unnamed',
]


def fresh_env(home: Path) -> dict[str, str]:
    return {
        'HOME': str(home), 'PATH': '/usr/local/bin:/usr/bin:/bin', 'TERM': 'dumb',
        'LANG': os.environ.get('LANG', 'C.UTF-8'),
        # this clone's virtualenv and workspace (tools/paths.sh keys them under $HOME)
        'TAC_CACHE_DIR': str(Path(os.environ['TAC_HOME']).parent),
        'ROS_LOG_DIR': str(home / 'ros_log'),
    }


def in_env_sh(script: str, home: Path, cwd: Path = REPO) -> subprocess.CompletedProcess[str]:
    """`script` in a fresh bash after `source ./env.sh` from the repository."""
    result = subprocess.run(['bash', '-c', f'source {REPO}/env.sh || exit 1\n{script}'],
                            cwd=cwd, env=fresh_env(home), capture_output=True, text=True,
                            timeout=SHELL_TIMEOUT_S, check=False, stdin=subprocess.DEVNULL)
    assert result.returncode == 0, f'{script}\nstdout:\n{result.stdout}\nstderr:\n{result.stderr}'
    return result


@pytest.fixture()
def home(tmp_path: Path) -> Path:
    path = tmp_path / 'home'
    path.mkdir()
    return path


def test_python_is_the_virtualenvs_in_env_sh_only(home: Path) -> None:
    outside = subprocess.run(['bash', '-c', 'command -v python || echo none'],
                             env=fresh_env(home), capture_output=True, text=True, check=True)
    inside = in_env_sh('command -v python; readlink -f "$(command -v python)"; '
                       'python -c "import sys; print(sys.version_info[0])"', home)
    python, target, major = inside.stdout.split()
    assert python == f'{os.environ["TAC_VENV"]}/bin/python'
    assert target.startswith('/usr/bin/python3') and major == '3'
    assert outside.stdout.strip() != python  # the machine's `python` (if any) is left alone
    print(f'figures: python outside env.sh: {outside.stdout.strip()}; inside: {python} '
          f'-> {target}')


def test_the_drc_era_modules_import_from_env_sh(home: Path) -> None:
    probe = ('import importlib\n'
             f'for name in {DRC_ERA_MODULES!r}:\n'
             '    module = importlib.import_module(name)\n'
             "    print(f'{name}: {module.__file__}')\n"
             "import roslib; roslib.load_manifest('tutorial_atlas_control')\n"
             "print('roslib.load_manifest(tutorial_atlas_control): ok')\n")
    result = in_env_sh(f"python - <<'EOF'\n{probe}EOF", home)
    lines = result.stdout.splitlines()
    print('figures: import test output:\n' + result.stdout)
    assert [line.split(': ')[0] for line in lines[:-1]] == list(DRC_ERA_MODULES)
    assert lines[-1] == 'roslib.load_manifest(tutorial_atlas_control): ok'
    assert result.stderr == ''


@pytest.mark.parametrize(('manifest', 'text'), [
    ('package.xml', CATKIN_PACKAGE_XML),
    ('manifest.xml', ROSBUILD_MANIFEST_XML),
])
def test_a_python_shebang_client_runs_with_rosrun_and_directly(
        tmp_path: Path, home: Path, manifest: str, text: str) -> None:
    package = tmp_path / 'ros' / PROBE_PACKAGE
    (package / 'scripts').mkdir(parents=True)
    (package / manifest).write_text(text)
    script = package / 'scripts' / CLIENT.name
    shutil.copy2(CLIENT, script)
    assert script.read_text().startswith('#!/usr/bin/env python\n')
    assert os.access(script, os.X_OK)
    path = f'export ROS_PACKAGE_PATH={package.parent}:$ROS_PACKAGE_PATH\n'
    for command, cwd in ((f'rosrun {PROBE_PACKAGE} {CLIENT.name}', REPO),
                         (f'./{CLIENT.name}', script.parent)):
        result = in_env_sh(path + command, home, cwd)
        lines = result.stdout.splitlines()
        assert lines[:-1] == CLIENT_OUTPUT, (command, result.stdout)
        assert lines[-1].startswith('python 3.') and lines[-1].endswith(
            f' at {os.environ["TAC_VENV"]}/bin/python'), lines[-1]
