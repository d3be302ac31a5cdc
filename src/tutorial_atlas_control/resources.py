"""Where the package's data lives, in a source tree and in a catkin install space.

In a source tree (a clone, or a catkin devel space whose src/ links to it) the data sits
beside src/: <repo>/sim, <repo>/config, ... In an install space (`catkin_make install`)
the code is in <prefix>/lib/python3/dist-packages/ and the data in
<prefix>/share/tutorial_atlas_control/. Every module asks here, so both layouts work.
The vendored message packages follow the same two layouts (<repo>/msg/<pkg>/msg/ and
<prefix>/share/<pkg>/msg/).
"""

from __future__ import annotations

from pathlib import Path

from tutorial_atlas_control.errors import AtlasControlError

PACKAGE_NAME = 'tutorial_atlas_control'
_MODULE_DIR = Path(__file__).resolve().parent


def _is_package_root(directory: Path) -> bool:
    manifest = directory / 'package.xml'
    return manifest.is_file() and f'<name>{PACKAGE_NAME}</name>' in manifest.read_text()


def _source_root() -> Path:
    return _MODULE_DIR.parents[1]  # <repo>/src/tutorial_atlas_control -> <repo>


def _install_share() -> Path:
    return _MODULE_DIR.parents[3] / 'share'  # <prefix>/lib/python3/dist-packages/<pkg>


def _candidates() -> list[Path]:
    return [_source_root(), _install_share() / PACKAGE_NAME]


def package_dir() -> Path:
    """The directory holding the package's data (package.xml, sim/, config/, ...).

    Raises:
        AtlasControlError: Neither layout holds the package's package.xml.
    """
    for candidate in _candidates():
        if _is_package_root(candidate):
            return candidate
    looked = ', '.join(str(c) for c in _candidates())
    raise AtlasControlError(f'cannot find the {PACKAGE_NAME} package data (looked in {looked});'
                            ' reinstall the package or run from its source tree')


def package_path(*parts: str) -> Path:
    """A path inside the package's data directory, e.g. package_path('sim', 'atlas_v1.xml')."""
    return package_dir().joinpath(*parts)


def message_file(package: str, name: str) -> Path | None:
    """The .msg file of a vendored message package (`osrf_msgs`, `JointCommands`), or None.

    Looked up beside the package's data (a source tree's msg/<pkg>/, an install space's
    share/<pkg>/), then on ROS_PACKAGE_PATH through rospkg where it is installed.
    """
    relative = Path('msg') / f'{name}.msg'
    candidates = [_source_root() / 'msg' / package / relative,
                  _install_share() / package / relative]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    try:
        import rospkg  # noqa: PLC0415 - optional: present only where ROS is installed

        candidate = Path(rospkg.RosPack().get_path(package)) / relative
    except Exception:  # noqa: BLE001 - rospkg missing or the package unknown: not found
        return None
    return candidate if candidate.is_file() else None
