"""launch_args.py: an argument roslaunch was given and no launch file declares (a typo such
as recrod:=false, which roslaunch ignores silently) gets one warning line."""

from __future__ import annotations

from pathlib import Path

from tutorial_atlas_control.launch_args import given_args, launch_files, unknown_arg_lines
from tutorial_atlas_control.resources import package_path

ATLAS_LAUNCH = package_path('launch', 'atlas.launch')


def find(package: str, name: str) -> Path | None:
    return ATLAS_LAUNCH if (package, name) == ('tutorial_atlas_control', 'atlas.launch') else None


def roslaunch(*args: str) -> list[str]:
    """roslaunch's command line as /proc shows it."""
    return ['/usr/bin/python3', '/usr/bin/roslaunch', '-p', '11311', 'tutorial_atlas_control',
            'atlas.launch', *args]


def test_a_typo_is_named_with_the_argument_meant() -> None:
    lines = unknown_arg_lines(roslaunch('gui:=false', 'recrod:=false'), find)
    assert len(lines) == 1
    assert lines[0].startswith('roslaunch ignored the argument recrod:=false: atlas.launch has '
                               'no argument recrod; did you mean record:=false? (its '
                               'arguments: atlas_state_rate, bag_dir, ')


def test_declared_arguments_remappings_and_unknown_files_say_nothing(tmp_path: Path) -> None:
    assert unknown_arg_lines(roslaunch('gui:=false', 'keep_bags:=3', '__name:=x',
                                       '_private:=1'), find) == []
    assert unknown_arg_lines(['roslaunch', 'other_pkg', 'x.launch', 'a:=1'], find) == []
    assert unknown_arg_lines(['roslaunch', '--core'], find) == []
    own = tmp_path / 'mine.launch'
    own.write_text('<launch><arg name="speed" default="1"/></launch>')
    assert launch_files(['roslaunch', str(own)], find) == [own]
    assert unknown_arg_lines(['roslaunch', str(own), 'sped:=2'], find) == [
        'roslaunch ignored the argument sped:=2: mine.launch has no argument sped; did you '
        'mean speed:=2? (its arguments: speed)']
    assert given_args(['a:=1', '__ns:=/x', 'b/c:=d', 'plain']) == {'a': '1'}
