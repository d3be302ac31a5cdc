"""What a subpackage offers, re-exported lazily from its __init__.py (PEP 562).

Each subpackage's __init__.py names its public names and the module defining each; a name
is imported from its module on first use. So `import tutorial_atlas_control.bags` stays
cheap (no MuJoCo, matplotlib or rosbags until a name needs them) and an __init__.py never
closes an import cycle: it imports nothing at import time.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping, Sequence
from typing import Any

__all__ = ['lazy_exports']


def lazy_exports(package: str, names_by_module: Mapping[str, Sequence[str]],
                 ) -> tuple[list[str], Callable[[str], Any], Callable[[], list[str]]]:
    """`__all__`, `__getattr__` and `__dir__` for the package `package`.

    Args:
        package: the package's `__name__`.
        names_by_module: submodule (relative to the package) -> the names it offers.

    Raises:
        ValueError: a name is offered by two modules.
    """
    module_of: dict[str, str] = {}
    for module, names in names_by_module.items():
        for name in names:
            if name in module_of:
                raise ValueError(f'{package}: {name} is offered by both {module_of[name]} '
                                 f'and {module}')
            module_of[name] = module

    def __getattr__(name: str) -> Any:
        module = module_of.get(name)
        if module is None:
            raise AttributeError(f'module {package!r} has no attribute {name!r}')
        value = getattr(importlib.import_module(f'{package}.{module}'), name)
        setattr(sys.modules[package], name, value)  # later uses skip __getattr__
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(module_of))

    return sorted(module_of), __getattr__, __dir__
