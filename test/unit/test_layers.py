"""The package's layer rules: rospy only on the ROS side, and the layers in one order.

The ROS side is node/ (the simulator node's machinery), cli/ (the scripts' command lines)
and every module named *_node.py: a program's rospy side, which lives beside the logic it
drives (trajectories/traj_yaml_node.py, plotting/plot_topics_node.py, ...). Everything else
must import without a ROS graph, so offline runs, replay and the bag tools work on a
machine without ROS and the simulation can be tested without it. Two checks, each shown
to fail on a deliberate violation:
- statically: no ROS-free module names a ROS client module in any import, at module level
  or inside a function, nor a ROS-side module (which would bring rospy in through it);
- at run time: every ROS-free module imports in a fresh interpreter whose import system
  refuses the ROS client modules.

The layers (LAYERS, lowest first): a module imports only from its own layer or lower ones,
and the units (subpackages and top-level modules) import each other without a cycle. Every
unit of the tree is placed in a layer, so a new one is placed deliberately.
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
#: The subpackages allowed to import rospy: the simulator node and the scripts' command lines.
ROSPY_LAYER = ('node', 'cli')
#: Elsewhere, a module whose name ends so is a program's ROS side (rospy allowed).
ROS_SIDE_SUFFIX = '_node'
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
    """A module of node/ or cli/, or a *_node module (or a name inside one)."""
    parts = name.split('.')
    if len(parts) < 2 or parts[0] != PACKAGE:
        return False
    return parts[1] in ROSPY_LAYER or any(part.endswith(ROS_SIDE_SUFFIX) for part in parts[1:])


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
    assert not violations, ('rospy belongs in node/, cli/ or a *_node.py module:\n'
                            + '\n'.join(violations))


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
        from tutorial_atlas_control.trajectories.traj_yaml_node import play
        from tutorial_atlas_control.plotting import plot_topics_node
    ''')
    found = layer_violations(source, f'{PACKAGE}.bags.example')
    assert found == [
        f'{PACKAGE}.bags.example:5: imports rospy',
        f'{PACKAGE}.bags.example:6: imports sensor_msgs.msg',
        f'{PACKAGE}.bags.example:7: imports {PACKAGE}.node (rospy layer)',
        f'{PACKAGE}.bags.example:8: imports {PACKAGE}.node.sim_node (rospy layer)',
        f'{PACKAGE}.bags.example:9: imports {PACKAGE}.cli (rospy layer)',
        f'{PACKAGE}.bags.example:10: imports {PACKAGE}.trajectories.traj_yaml_node (rospy layer)',
        f'{PACKAGE}.bags.example:11: imports {PACKAGE}.plotting.plot_topics_node (rospy layer)',
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


# -- The layers' order --------------------------------------------------------------------
#: The units (subpackages and top-level modules) by layer, lowest first. Why each sits where
#: it does: the facts (names, units, errors, paths) need nothing; the command model is what
#: msgs' decoders produce and sim's law reads, so it sits below both; native (the compiled
#: library's binding) mirrors the command's fields for the compiled law; msgs are the wire
#: formats, plotting reads messages; course describes the VRC course (its figures, world,
#: mud and scoring: pure, below the simulator that loads and steps it); sim fills messages
#: from the simulator; balance (the
#: behaviours' controllers) computes torques over the model sim loads, and stereo renders the
#: head's cameras in a copy of it; walking plans steps
#: on the balance's pendulum; stepping (the live loop) and trajectories run the simulation;
#: bags read recorded runs, of trajectories; offline runs write and replay bags, demo runs
#: the tutorial and reads its bag; search sweeps offline runs; node is the simulator node
#: over all of these; cli, each script's command line, over everything.
LAYERS: tuple[tuple[str, ...], ...] = (
    ('', 'control_modes', 'errors', 'exports', 'fall_report', 'grids', 'joints', 'launch_args',
     'processes', 'resources', 'topics', 'units', 'yaml_errors'),
    ('command',),
    ('native',),
    ('msgs', 'plotting'),
    ('course',),
    ('sim',),
    ('sensors',),
    ('balance', 'stereo'),
    ('walking',),
    ('asi',),
    ('stepping', 'trajectories'),
    ('bags',),
    ('offline', 'demo'),
    ('search',),
    ('node',),
    ('cli',),
)
LAYER_OF = {unit: rank for rank, units in enumerate(LAYERS) for unit in units}


def unit_of(name: str) -> str | None:
    """The unit a module of the package belongs to ('' for the package itself), or None for
    a module outside the package."""
    parts = name.split('.')
    if parts[0] != PACKAGE:
        return None
    return parts[1] if len(parts) > 1 else ''


def package_units() -> set[str]:
    return {unit_of(module_name(path)) or '' for path in PACKAGE_DIR.rglob('*.py')}


def layer_order_violations(source: str, current: str) -> list[str]:
    """What `source` (the module `current`) imports from a higher layer, or from a unit
    LAYERS does not place: one line per offending import statement."""
    own = LAYER_OF.get(unit_of(current) or '')
    found = []
    for line, names in imported_names(source, current):
        for name in names:
            unit = unit_of(name)
            if unit is None or unit == '':
                continue
            layer = LAYER_OF.get(unit)
            if layer is None or own is None:
                found.append(f'{current}:{line}: imports {name} (in no layer)')
                break
            if layer > own:
                found.append(f'{current}:{line}: imports {name} (layer {layer} above layer {own})')
                break
    return found


def unit_edges() -> dict[str, set[str]]:
    """unit -> the other units its modules import."""
    edges: dict[str, set[str]] = {}
    for path in PACKAGE_DIR.rglob('*.py'):
        current = module_name(path)
        importer = unit_of(current) or ''
        for _, names in imported_names(path.read_text(), current):
            for name in names:
                unit = unit_of(name)
                if unit and unit != importer and unit in package_units():
                    edges.setdefault(importer, set()).add(unit)
    return edges


def find_cycle(edges: dict[str, set[str]]) -> list[str]:
    """One cycle of the directed graph `edges` as [a, b, ..., a], or [] if it has none."""
    done: set[str] = set()

    def visit(node: str, path: list[str]) -> list[str]:
        if node in path:
            return path[path.index(node):] + [node]
        if node in done:
            return []
        for target in sorted(edges.get(node, ())):
            cycle = visit(target, path + [node])
            if cycle:
                return cycle
        done.add(node)
        return []

    for start in sorted(edges):
        cycle = visit(start, [])
        if cycle:
            return cycle
    return []


def test_every_unit_of_the_package_has_a_layer() -> None:
    units = package_units()
    assert units - set(LAYER_OF) == set(), 'place each new subpackage or module in LAYERS'
    assert set(LAYER_OF) - units == set(), 'LAYERS names units the package no longer has'


def test_modules_import_only_from_their_own_or_lower_layers() -> None:
    violations = []
    for path in sorted(PACKAGE_DIR.rglob('*.py')):
        violations += layer_order_violations(path.read_text(), module_name(path))
    assert not violations, 'an import goes up the layers (LAYERS):\n' + '\n'.join(violations)


def test_the_layer_check_catches_upward_imports() -> None:
    source = textwrap.dedent('''
        import numpy as np
        from tutorial_atlas_control import errors, topics
        from tutorial_atlas_control.command.arrays import LAW_FIELDS
        from tutorial_atlas_control.msgs.wire import ImuWire
        from tutorial_atlas_control.plotting.fields import PlotError
        from tutorial_atlas_control.sim.simulator import AtlasSimulator
        def later():
            from tutorial_atlas_control.offline import player
        from ..bags import reader
        from tutorial_atlas_control import native, stepping
        from tutorial_atlas_control.nowhere import thing
    ''')
    found = layer_order_violations(source, f'{PACKAGE}.msgs.example')
    assert found == [
        f'{PACKAGE}.msgs.example:7: imports {PACKAGE}.sim.simulator (layer 5 above layer 3)',
        f'{PACKAGE}.msgs.example:9: imports {PACKAGE}.offline (layer 12 above layer 3)',
        f'{PACKAGE}.msgs.example:10: imports {PACKAGE}.bags (layer 11 above layer 3)',
        f'{PACKAGE}.msgs.example:11: imports {PACKAGE}.stepping (layer 10 above layer 3)',
        f'{PACKAGE}.msgs.example:12: imports {PACKAGE}.nowhere (in no layer)',
    ]


def test_the_units_import_each_other_without_a_cycle() -> None:
    edges = unit_edges()
    assert edges['sim'] >= {'command', 'native', 'msgs'}, 'the import graph was not read'
    assert find_cycle(edges) == []


def test_the_cycle_check_catches_a_cycle() -> None:
    edges = {'msgs': {'command', 'sim'}, 'sim': {'command', 'native'}, 'native': {'msgs'}}
    assert find_cycle(edges) == ['msgs', 'sim', 'native', 'msgs']
    assert find_cycle({'msgs': {'command'}, 'sim': {'msgs', 'command'}}) == []
