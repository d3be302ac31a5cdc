"""The install rules name everything an install space needs (no wildcards: each file listed).

A script, subpackage or data directory added without its install rule works in the source
tree and devel space and fails only from `catkin_make install`; these checks name the
missing rule at once (test/integration/test_install_space.py runs the installed package).
"""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PACKAGE = 'tutorial_atlas_control'
PACKAGE_DIR = REPO / 'src' / PACKAGE
#: Where the package's executables live in the source tree (rosrun finds them installed).
EXECUTABLE_DIRS = ('scripts', 'sim')
EXECUTABLE_BITS = 0o111


def cmake_calls(command: str) -> list[list[str]]:
    """The arguments of every `command(...)` in CMakeLists.txt, comments removed."""
    text = re.sub(r'#[^\n]*', '', (REPO / 'CMakeLists.txt').read_text())
    return [call.split() for call in re.findall(rf'\b{command}\(([^)]*)\)', text)]


def listed(command: str, keyword: str) -> set[str]:
    """The files named after `keyword` (PROGRAMS, DIRECTORY) up to DESTINATION."""
    found = set()
    for arguments in cmake_calls(command):
        if arguments and arguments[0] == keyword:
            found.update(arguments[1:arguments.index('DESTINATION')])
    return found


def executables() -> set[str]:
    return {str(path.relative_to(REPO)) for directory in EXECUTABLE_DIRS
            for path in (REPO / directory).iterdir()
            if path.is_file() and path.stat().st_mode & EXECUTABLE_BITS}


def test_every_executable_is_installed_python_through_catkin_install_python() -> None:
    python, other = listed('catkin_install_python', 'PROGRAMS'), listed('install', 'PROGRAMS')
    missing = executables() - (python | other)
    assert not missing, f'add to catkin_install_python (or install(PROGRAMS)): {sorted(missing)}'
    assert python | other == executables()
    assert all(name.endswith('.py') for name in python)  # its shebang becomes catkin's Python
    assert not any(name.endswith('.py') for name in other)


def test_every_subpackage_is_in_setup_py() -> None:
    subpackages = {'.'.join(path.parent.relative_to(PACKAGE_DIR.parent).parts)
                   for path in PACKAGE_DIR.rglob('__init__.py')}
    named = set(re.findall(rf"'({PACKAGE}(?:\.\w+)*)'", (REPO / 'setup.py').read_text()))
    assert subpackages - named == set(), 'add to setup.py packages: catkin installs only those'
    assert subpackages == named


def test_every_data_directory_the_code_and_launch_files_use_is_installed() -> None:
    used = set()
    for path in PACKAGE_DIR.rglob('*.py'):
        used.update(re.findall(r"package_path\('(\w+)'", path.read_text()))
    for path in (REPO / 'launch').glob('*.launch'):
        used.update(re.findall(rf'\$\(find {PACKAGE}\)/(\w+)/', path.read_text()))
    assert {'config', 'sim', 'trajectories', 'rviz'} <= used  # the scan finds the uses
    assert used | {'launch'} <= listed('install', 'DIRECTORY')


def test_the_checks_read_the_rules_they_judge() -> None:
    """The parsing above sees today's rules (a parser that finds nothing passes nothing)."""
    assert 'sim/atlas_sim_node.py' in listed('catkin_install_python', 'PROGRAMS')
    assert listed('install', 'PROGRAMS') == {'scripts/record_run.sh'}
    assert 'scripts/traj_yaml.py' in executables()
