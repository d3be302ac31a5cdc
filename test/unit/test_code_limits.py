"""Size limits on the package's code, so that no class, function or constructor grows back.

A restructuring once brought the stepping loop under these limits and within a day it had
grown back to 525 lines: nothing kept it. Each class stays at most MAX_CLASS_LINES long,
each function or method at most MAX_FUNCTION_LINES (decorators and docstring included),
and each constructor takes at most MAX_INIT_PARAMETERS besides `self` (keyword-only ones
counted; `*args`/`**kwargs` count one each). A collaborator with a narrow interface is the
way out of all three.
"""

from __future__ import annotations

import ast
import textwrap
from pathlib import Path

SOURCE_DIR = Path(__file__).resolve().parents[2] / 'src'
MAX_CLASS_LINES = 250
MAX_FUNCTION_LINES = 60
MAX_INIT_PARAMETERS = 7


def _lines(node: ast.AST) -> int:
    decorators = getattr(node, 'decorator_list', [])
    first = min([node.lineno] + [d.lineno for d in decorators])
    return node.end_lineno - first + 1


def _parameters(function: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    args = function.args
    positional = [a.arg for a in args.posonlyargs + args.args]
    if positional and positional[0] in ('self', 'cls'):
        positional = positional[1:]
    variadic = (args.vararg is not None) + (args.kwarg is not None)
    return len(positional) + len(args.kwonlyargs) + variadic


def limit_violations(source: str, where: str) -> list[str]:
    """One line per class, function or constructor of `source` over the limits."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ClassDef) and _lines(node) > MAX_CLASS_LINES:
            found.append(f'{where}:{node.lineno}: class {node.name} has {_lines(node)} lines '
                         f'(at most {MAX_CLASS_LINES})')
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            if _lines(node) > MAX_FUNCTION_LINES:
                found.append(f'{where}:{node.lineno}: function {node.name} has {_lines(node)} '
                             f'lines (at most {MAX_FUNCTION_LINES})')
            if node.name == '__init__' and _parameters(node) > MAX_INIT_PARAMETERS:
                found.append(f'{where}:{node.lineno}: __init__ takes {_parameters(node)} '
                             f'parameters (at most {MAX_INIT_PARAMETERS})')
    return found


def test_the_package_keeps_its_size_limits() -> None:
    paths = sorted(SOURCE_DIR.rglob('*.py'))
    assert len(paths) > 50, 'the package was not found'
    violations = []
    for path in paths:
        violations += limit_violations(path.read_text(), str(path.relative_to(SOURCE_DIR)))
    assert not violations, 'split these by concern:\n' + '\n'.join(violations)


def test_the_check_catches_each_kind_of_violation() -> None:
    long_body = '\n'.join(f'        x{i} = {i}' for i in range(MAX_FUNCTION_LINES))
    source = textwrap.dedent('''
        class Small:
            def __init__(self, a, b, c, d, e, f, g, *, h):
                pass

            @staticmethod
            def fits():
                pass
    ''') + 'class Big:\n    def long(self):\n' + long_body + '\n' + ''.join(
        f'    def m{i}(self):\n        pass\n' for i in range(MAX_CLASS_LINES // 2))
    found = limit_violations(source, 'x.py')
    assert [line.split(': ', 1)[1] for line in found] == [
        f'class Big has {2 + MAX_FUNCTION_LINES + MAX_CLASS_LINES} lines (at most 250)',
        '__init__ takes 8 parameters (at most 7)',
        f'function long has {1 + MAX_FUNCTION_LINES} lines (at most 60)',
    ]


def test_limits_are_met_exactly_at_the_bound() -> None:
    body = '\n'.join(f'    x{i} = {i}' for i in range(MAX_FUNCTION_LINES - 1))
    source = ('def at_bound():\n' + body + '\n\n'
              'class C:\n    def __init__(self, a, b, c, d, e, f, g):\n        pass\n')
    assert limit_violations(source, 'x.py') == []
