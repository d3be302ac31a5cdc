"""A YAML parse error as one line, for the files users edit (trajectories, gains)."""

from __future__ import annotations

import yaml

__all__ = ['yaml_problem', 'yaml_where']


def yaml_where(err: yaml.YAMLError) -> str:
    """` at line L, column C` (1-based) of the error's mark, or '' if it has none."""
    mark = getattr(err, 'problem_mark', None) or getattr(err, 'context_mark', None)
    return f' at line {mark.line + 1}, column {mark.column + 1}' if mark is not None else ''


def yaml_problem(err: yaml.YAMLError) -> str:
    """`invalid YAML at line L, column C: what` on one line."""
    problem = getattr(err, 'problem', None) or ' '.join(str(err).split())
    return f'invalid YAML{yaml_where(err)}: {problem}'
