"""Each subpackage says what it offers: a docstring and an `__all__` whose every name
resolves, lazily (exports.lazy_exports), so importing a subpackage imports none of its
modules."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from tutorial_atlas_control.exports import lazy_exports

PACKAGE = 'tutorial_atlas_control'
PACKAGE_DIR = Path(__file__).resolve().parents[2] / 'src' / PACKAGE
SUBPACKAGES = sorted(path.parent.name for path in PACKAGE_DIR.glob('*/__init__.py'))


def test_the_subpackages_are_found() -> None:
    assert {'bags', 'command', 'msgs', 'sim', 'stepping', 'node', 'cli'} <= set(SUBPACKAGES)


@pytest.mark.parametrize('name', SUBPACKAGES)
def test_every_name_in_all_resolves(name: str) -> None:
    package = importlib.import_module(f'{PACKAGE}.{name}')
    assert (package.__doc__ or '').strip(), f'{name}/__init__.py says nothing of what it offers'
    assert isinstance(package.__all__, list)
    assert len(set(package.__all__)) == len(package.__all__)
    missing = [attribute for attribute in package.__all__ if not hasattr(package, attribute)]
    assert not missing, f'{name}.__all__ names what its modules do not define: {missing}'
    assert set(package.__all__) <= set(dir(package))


def test_a_bad_name_in_all_fails_to_resolve(tmp_path: Path) -> None:
    (tmp_path / 'offers').mkdir()
    (tmp_path / 'offers' / '__init__.py').write_text(textwrap.dedent('''
        from tutorial_atlas_control.exports import lazy_exports
        __all__, __getattr__, __dir__ = lazy_exports(__name__, {'shapes': ['Circle', 'Square']})
    '''))
    (tmp_path / 'offers' / 'shapes.py').write_text('class Circle:\n    pass\n')
    sys.path.insert(0, str(tmp_path))
    try:
        offers = importlib.import_module('offers')
        assert offers.__all__ == ['Circle', 'Square']
        assert offers.Circle.__name__ == 'Circle'
        assert not hasattr(offers, 'Square')
        with pytest.raises(AttributeError, match="module 'offers' has no attribute 'Triangle'"):
            offers.Triangle  # noqa: B018 - the lookup is the test
    finally:
        sys.path.remove(str(tmp_path))
        for module in ('offers', 'offers.shapes'):
            sys.modules.pop(module, None)


def test_a_name_offered_twice_is_refused() -> None:
    with pytest.raises(ValueError, match='offers: to_json is offered by both compare and report'):
        lazy_exports('offers', {'compare': ['to_json'], 'report': ['to_json']})


def test_importing_a_subpackage_imports_none_of_its_modules() -> None:
    """Lazy: `import tutorial_atlas_control.sim` loads neither MuJoCo nor sim's modules."""
    code = textwrap.dedent(f'''
        import sys
        for name in {SUBPACKAGES!r}:
            __import__('{PACKAGE}.' + name)
        loaded = sorted(m for m in sys.modules if m.startswith('{PACKAGE}.')
                        and m.count('.') > 1)
        print(loaded, 'mujoco' in sys.modules)
    ''')
    result = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                            timeout=60, check=True)
    assert result.stdout.strip() == '[] False'


def through_the_package_violations(source: str, current: str) -> list[str]:
    """What module `current` (a dotted name) imports from another subpackage without going
    through that subpackage's __init__: a module of it (`from pkg.sim.model import x`), or a
    name its __all__ does not offer (`from pkg.sim import model`). A ROS-side `*_node`
    module is imported by its path (it is no part of its package's API)."""
    own = current.split('.')[1] if current.count('.') >= 2 else None
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            modules = [(node.module, [alias.name for alias in node.names])]
        elif isinstance(node, ast.Import):
            modules = [(alias.name, []) for alias in node.names]
        else:
            continue
        for module, names in modules:
            parts = module.split('.')
            if parts[0] != PACKAGE or len(parts) < 2 or parts[1] not in SUBPACKAGES:
                continue
            if parts[1] == own or parts[-1].endswith('_node'):
                continue
            if len(parts) > 2:
                found.append(f'{current}:{node.lineno}: imports {module}, not through '
                             f'{PACKAGE}.{parts[1]}')
                continue
            offered = importlib.import_module(module).__all__
            extra = [name for name in names if name not in offered and not name.endswith('_node')]
            if extra:
                found.append(f'{current}:{node.lineno}: {module} does not offer {extra}')
    return found


def test_other_packages_import_through_the_init() -> None:
    violations = []
    for path in sorted(PACKAGE_DIR.rglob('*.py')):
        relative = path.relative_to(PACKAGE_DIR.parent).with_suffix('')
        parts = relative.parts[:-1] if relative.name == '__init__' else relative.parts
        violations += through_the_package_violations(path.read_text(), '.'.join(parts))
    assert not violations, 'import through the subpackage:\n' + '\n'.join(violations)


def test_the_through_check_catches_deep_imports() -> None:
    source = textwrap.dedent(f'''
        from {PACKAGE}.sim import AtlasSimulator
        from {PACKAGE}.sim.model import load_model
        import {PACKAGE}.bags.reader
        from {PACKAGE}.sim import model
        from {PACKAGE}.trajectories.traj_yaml_node import main
        from {PACKAGE}.stepping.loop import SteppingLoop
        from {PACKAGE} import joints
    ''')
    found = through_the_package_violations(source, f'{PACKAGE}.stepping.example')
    assert found == [
        f'{PACKAGE}.stepping.example:3: imports {PACKAGE}.sim.model, not through {PACKAGE}.sim',
        f'{PACKAGE}.stepping.example:4: imports {PACKAGE}.bags.reader, not through '
        f'{PACKAGE}.bags',
        f"{PACKAGE}.stepping.example:5: {PACKAGE}.sim does not offer ['model']",
    ]
