"""launch_args.py: an argument roslaunch was given and no launch file declares (a typo such
as recrod:=false, which roslaunch ignores silently) gets one warning line."""

from __future__ import annotations

from pathlib import Path

from tutorial_atlas_control.launch_args import (
    declared_args,
    given_args,
    included_file,
    launch_files,
    unknown_arg_lines,
)
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


def package_launch(package: str, name: str) -> Path | None:
    """The package's launch files, as the simulator finds them."""
    path = ATLAS_LAUNCH.parent / name
    return path if package == 'tutorial_atlas_control' and path.is_file() else None


def test_the_vrc_launches_take_atlas_launchs_arguments_through_their_includes() -> None:
    """vrc_task_2_mud_start.launch includes vrc_task_2.launch, which includes atlas.launch,
    each with pass_all_args: record:=false reaches atlas.launch and is not warned about."""
    argv = ['roslaunch', 'tutorial_atlas_control', 'vrc_task_2_mud_start.launch',
            'gzname:=gzserver', 'record:=false', 'score_dir:=/tmp/x', 'start:=1 2 0 0']
    assert unknown_arg_lines(argv, package_launch) == []
    lines = unknown_arg_lines([*argv, 'gzame:=gazebo'], package_launch)
    assert len(lines) == 1
    assert lines[0].startswith('roslaunch ignored the argument gzame:=gazebo: '
                               'vrc_task_2_mud_start.launch has no argument gzame; did you mean '
                               'gzname:=gazebo?')


def test_includes_are_followed_only_where_they_can_be_found(tmp_path: Path) -> None:
    inner = tmp_path / 'inner.launch'
    inner.write_text('<launch><arg name="speed" default="1"/></launch>')
    outer = tmp_path / 'outer.launch'
    outer.write_text('<launch><arg name="mode" default="a"/>'
                     '<include file="$(dirname)/inner.launch" pass_all_args="true"/>'
                     '<include file="$(dirname)/outer.launch" pass_all_args="true"/></launch>')
    assert declared_args(outer, package_launch) == {'mode', 'speed'}  # a cycle ends
    assert declared_args(outer) == {'mode'}  # no finder: the file's own
    assert included_file(outer, '$(find tutorial_atlas_control)/launch/atlas.launch',
                         package_launch) == ATLAS_LAUNCH
    assert included_file(outer, '$(find other_pkg)/launch/x.launch', package_launch) is None
    assert included_file(outer, '/abs/path.launch', package_launch) is None
    hidden = tmp_path / 'hidden.launch'
    hidden.write_text('<launch><include file="$(env X)/y.launch" pass_all_args="true"/>'
                      '</launch>')
    # An include it cannot read: nothing can be said, so no warning at all.
    assert unknown_arg_lines(['roslaunch', str(hidden), 'anything:=1'], package_launch) == []
