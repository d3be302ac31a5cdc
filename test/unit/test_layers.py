"""The package's layer rule: rospy lives in node/ and cli/ only.

Everything else (the facts modules, sim/, msgs/, stepping/, trajectories/, bags/, offline/)
must import without a ROS graph, so offline runs, replay and the bag tools work on a
machine without ROS and the simulation can be tested without it. Two checks, each shown
to fail on a deliberate violation:
- statically: no module of the ROS-free layer names a ROS client module in any import, at
  module level or inside a function, nor a module of the rospy layer (which would bring
  rospy in through another module);
- at run time: every ROS-free module imports in a fresh interpreter whose import system
  refuses the ROS client modules.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
import textwrap
from pathlib import Path

PACKAGE = 'tutorial_atlas_control'
PACKAGE_DIR = Path(__file__).resolve().parents[2] / 'src' / PACKAGE
#: The subpackages allowed to import rospy: the ROS nodes and the scripts' command lines.
ROSPY_LAYER = ('node', 'cli')
#: Top-level modules of ROS 1's Python client side. rospkg (package paths, no graph) and
#: rosbags (pure Python bags) are not among them.
ROS_CLIENT_MODULES = frozenset({
    'rospy', 'rosgraph', 'genpy', 'roslib', 'rosbag', 'rostest', 'roslaunch', 'rosnode',
    'rosservice', 'rostopic', 'tf', 'tf2_ros', 'std_srvs', 'message_filters',
})


def is_ros_client_module(name: str) -> bool:
    """A ROS client module, or a generated message package (`sensor_msgs.msg`, ...)."""
    top = name.split('.')[0]
    return top in ROS_CLIENT_MODULES or top.endswith('_msgs')


def module_name(path: Path) -> str:
    relative = path.relative_to(PACKAGE_DIR.parent).with_suffix('')
    parts = relative.parts[:-1] if relative.name == '__init__' else relative.parts
    return '.'.join(parts)


def in_rospy_layer(name: str) -> bool:
    parts = name.split('.')
    return len(parts) > 1 and parts[0] == PACKAGE and parts[1] in ROSPY_LAYER


def ros_free_modules() -> list[Path]:
    return sorted(p for p in PACKAGE_DIR.rglob('*.py') if not in_rospy_layer(module_name(p)))


def imported_names(source: str, current: str) -> list[tuple[int, list[str]]]:
    """(line, modules) of every import statement in `source`, anywhere in it: `from a
    import b` may import the module a.b, so it names both; relative imports are resolved
    against the module `current`."""
    statements = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            statements.append((node.lineno, [alias.name for alias in node.names]))
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ''
            if node.level:
                anchor = current.split('.')[:-node.level]
                base = '.'.join(anchor + ([base] if base else []))
            statements.append((node.lineno, [base] + [f'{base}.{a.name}' for a in node.names]))
    return sorted(statements)


def layer_violations(source: str, current: str) -> list[str]:
    """What `source` (the module `current`, in the ROS-free layer) imports against the rule:
    one line per offending import statement."""
    found = []
    for line, names in imported_names(source, current):
        for name in names:
            if is_ros_client_module(name):
                found.append(f'{current}:{line}: imports {name}')
                break
            if in_rospy_layer(name):
                found.append(f'{current}:{line}: imports {name} (rospy layer)')
                break
    return found


def test_the_ros_free_layer_names_no_ros_client_module() -> None:
    violations = []
    for path in ros_free_modules():
        violations += layer_violations(path.read_text(), module_name(path))
    assert not violations, 'rospy belongs in node/ or cli/:\n' + '\n'.join(violations)


def test_the_static_check_catches_violations() -> None:
    source = textwrap.dedent('''
        import numpy as np
        from tutorial_atlas_control import topics
        def later():
            import rospy
            from sensor_msgs.msg import JointState
        from tutorial_atlas_control.node import transport
        from ..node.sim_node import SimNode
        from tutorial_atlas_control import cli
    ''')
    found = layer_violations(source, f'{PACKAGE}.bags.example')
    assert found == [
        f'{PACKAGE}.bags.example:5: imports rospy',
        f'{PACKAGE}.bags.example:6: imports sensor_msgs.msg',
        f'{PACKAGE}.bags.example:7: imports {PACKAGE}.node (rospy layer)',
        f'{PACKAGE}.bags.example:8: imports {PACKAGE}.node.sim_node (rospy layer)',
        f'{PACKAGE}.bags.example:9: imports {PACKAGE}.cli (rospy layer)',
    ]


#: Run in a fresh interpreter: refuse the ROS client modules, then import every module
#: named on the command line; print the ones that failed.
IMPORT_WITHOUT_ROS = textwrap.dedent('''
    import importlib, importlib.abc, sys
    REFUSED = set(sys.argv[1].split(','))

    class RefuseRos(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            top = name.split('.')[0]
            if top in REFUSED or top.endswith('_msgs'):
                raise ImportError(f'{name} is refused: this layer must not need ROS')
            return None

    sys.meta_path.insert(0, RefuseRos())
    failed = []
    for name in sys.argv[2:]:
        try:
            importlib.import_module(name)
        except Exception as err:
            failed.append(f'{name}: {type(err).__name__}: {err}')
    print('\\n'.join(failed))
    sys.exit(1 if failed else 0)
''')


def import_without_ros(names: list[str],
                       extra_path: Path | None = None) -> subprocess.CompletedProcess[str]:
    paths = [str(PACKAGE_DIR.parent)] + ([str(extra_path)] if extra_path else [])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(paths + [os.environ.get('PYTHONPATH', '')]))
    return subprocess.run(
        [sys.executable, '-c', IMPORT_WITHOUT_ROS, ','.join(sorted(ROS_CLIENT_MODULES)), *names],
        capture_output=True, text=True, timeout=120, env=env)


def test_the_ros_free_layer_imports_with_ros_refused() -> None:
    names = [module_name(p) for p in ros_free_modules()]
    result = import_without_ros(names)
    assert result.returncode == 0, result.stdout + result.stderr


def test_the_import_check_catches_a_module_that_needs_rospy(tmp_path: Path) -> None:
    (tmp_path / 'needs_ros_through_another.py').write_text('import needs_ros_directly\n')
    (tmp_path / 'needs_ros_directly.py').write_text('import rospy\n')
    result = import_without_ros(['needs_ros_through_another'], extra_path=tmp_path)
    assert result.returncode == 1
    assert 'needs_ros_through_another: ImportError: rospy is refused' in result.stdout
