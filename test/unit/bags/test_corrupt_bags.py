"""Damaged bags given to analyze_bag.py, replay_bag.py and analyze_bag.py --compare.

Each damage gives one line on stderr (`<prog>: error: ...`) and exit status 1, never a
traceback: a truncated bag (cut in its header, a chunk or its index), a wrong MD5 on a
topic the tools decode, a compressed chunk whose bytes are damaged. A bag without
/atlas/sim_config is no damage: the analysis does not need it, and replay says in one
warning that it assumes the defaults (an older bag) with --assume-defaults, and one line
and exit 1 without it.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from support import synthetic_bags as synthetic
from tutorial_atlas_control.bags.reader import JOINT_STATE_MD5
from tutorial_atlas_control.cli import analyze_bag, replay_bag

WRONG_MD5 = '0123456789abcdef0123456789abcdef'
TRUNCATED = ('is truncated or its index is damaged (was the recording cut short?); run '
             '`rosbag reindex {bag}` and analyze it again.')


def _good(directory: Path, compression: str | None = None) -> Path:
    return synthetic.write_bag(directory / f'good_{compression}.bag',
                               synthetic.run_records(1.0) + [synthetic.sim_config(0.0, 0.0)],
                               compression=compression, chunk_bytes=64 * 1024)


@pytest.fixture(scope='module')
def bags(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    directory = tmp_path_factory.mktemp('corrupt')
    good = _good(directory)
    raw = good.read_bytes()
    made = {'good': good}
    for name, size in (('cut_in_header', 100), ('cut_in_a_chunk', len(raw) * 3 // 10),
                       ('cut_in_the_index', len(raw) - 50)):
        made[name] = directory / f'{name}.bag'
        made[name].write_bytes(raw[:size])
    made['wrong_md5'] = directory / 'wrong_md5.bag'
    made['wrong_md5'].write_bytes(raw.replace(JOINT_STATE_MD5.encode(), WRONG_MD5.encode()))
    lz4 = bytearray(_good(directory, 'lz4').read_bytes())
    at = len(lz4) * 45 // 100
    lz4[at:at + 64] = bytes(byte ^ 0x5A for byte in lz4[at:at + 64])
    made['damaged_lz4_chunk'] = directory / 'damaged_lz4_chunk.bag'
    made['damaged_lz4_chunk'].write_bytes(bytes(lz4))
    made['no_sim_config'] = synthetic.write_bag(directory / 'no_sim_config.bag',
                                                synthetic.run_records(1.0))
    return made


def _expected(name: str, bag: Path) -> str:
    if name.startswith('cut_in'):
        return f'{bag} ' + TRUNCATED.format(bag=bag)
    if name == 'wrong_md5':
        return (f'{bag}: /atlas/joint_states is recorded as sensor_msgs/JointState with MD5 '
                f'{WRONG_MD5}, but sensor_msgs/JointState has MD5 {JOINT_STATE_MD5}: the bag is '
                'damaged or was recorded with another version of the message; it cannot be '
                'read.')
    assert name == 'damaged_lz4_chunk'
    return f'Could not read {bag}, a message is damaged (ReaderError: the chunk at byte '


TOOLS: dict[str, tuple[str, Callable[[Path, Path], list[str]]]] = {
    'analyze': ('analyze_bag.py', lambda bag, _good: [str(bag)]),
    'replay': ('replay_bag.py', lambda bag, _good: [str(bag)]),
    'compare_a': ('analyze_bag.py', lambda bag, good: [str(bag), '--compare', str(good)]),
    'compare_b': ('analyze_bag.py', lambda bag, good: [str(good), '--compare', str(bag)]),
}


@pytest.mark.parametrize('tool', TOOLS)
@pytest.mark.parametrize('name', ['cut_in_header', 'cut_in_a_chunk', 'cut_in_the_index',
                                  'wrong_md5', 'damaged_lz4_chunk'])
def test_a_damaged_bag_is_one_line_and_exit_1(bags: dict[str, Path], name: str, tool: str,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    prog, arguments = TOOLS[tool]
    main = replay_bag.main if tool == 'replay' else analyze_bag.main
    assert main(arguments(bags[name], bags['good'])) == 1
    out, err = capsys.readouterr()
    assert out == ''
    assert err.count('\n') == 1 and 'Traceback' not in err, err
    assert err.startswith(f'{prog}: error: {_expected(name, bags[name])}'), err


def test_a_bag_without_sim_config_is_analyzed_and_replayed_only_on_request(
        bags: dict[str, Path], capsys: pytest.CaptureFixture[str]) -> None:
    """The analysis needs no sim_config; a replay does (the pin time, the last reset)."""
    bag = bags['no_sim_config']
    assert analyze_bag.main([str(bag)]) == 0
    assert analyze_bag.main([str(bag), '--compare', str(bags['good'])]) == 0
    capsys.readouterr()
    assert replay_bag.main([str(bag)]) == 1
    out, err = capsys.readouterr()
    assert out == '' and err == (
        f'replay_bag.py: error: {bag} has no /atlas/sim_config (not recorded by atlas.launch, '
        'or before the simulator published it): the pin time and the last reset are unknown; '
        '--assume-defaults replays it with time_to_unpin = 1.0 s and no reset after '
        't = 0.0 s.\n')
    assert replay_bag.main([str(bag), '--assume-defaults']) in (0, 3)  # 3: no physics
    out, err = capsys.readouterr()
    warnings = [line for line in out.splitlines() if line.lstrip().startswith('warning:')]
    assert len(warnings) == 1 and 'the bag has no /atlas/sim_config' in warnings[0], out
    assert 'assuming time_to_unpin = 1.0 s' in warnings[0]
    assert 'Traceback' not in out + err
