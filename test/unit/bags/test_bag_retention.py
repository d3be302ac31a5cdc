"""Bag housekeeping (bags/retention.py, cli/bag_housekeeping.py): the launch's usage line,
keep_bags / max_bags_mb retention counting the run's own bag, and `make clean-bags`."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tutorial_atlas_control.bags.retention import (
    BagFile,
    Retention,
    RetentionError,
    bag_files,
    bags_count,
    doomed,
    retention_from_env,
)
from tutorial_atlas_control.cli import bag_housekeeping

MB = 1_000_000


def make_bags(directory: Path, sizes_mb: list[int]) -> list[Path]:
    """atlas_<k>.bag files of `sizes_mb`, oldest first (mtimes 1000 s apart)."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for index, size in enumerate(sizes_mb):
        path = directory / f'atlas_2026-01-01-00-00-{index:02d}.bag'
        with path.open('wb') as stream:
            stream.truncate(size * MB)  # sparse: the size counts, not the blocks
        os.utime(path, (1_000_000 + 1000 * index,) * 2)
        paths.append(path)
    return paths


def files(sizes_mb: list[int]) -> list[BagFile]:
    return [BagFile(Path(f'b{k}.bag'), size * MB, float(k)) for k, size in enumerate(sizes_mb)]


@pytest.mark.parametrize(('retention', 'coming', 'deleted'), [
    (Retention(), 1, 0),                        # off
    (Retention(keep_bags=3), 0, 2),             # 5 -> 3
    (Retention(keep_bags=3), 1, 3),             # 5 + the run's -> 3
    (Retention(keep_bags=1), 1, 5),             # only the run's own
    (Retention(max_bytes=25 * MB), 0, 2),       # 10+10+10+5+5 = 40 MB -> 10+5+5 = 20 MB
    (Retention(max_bytes=40 * MB), 1, 0),       # exactly at the cap
    (Retention(keep_bags=4, max_bytes=15 * MB), 1, 3),  # the size cap binds
])
def test_the_oldest_go_first_until_both_limits_hold(retention: Retention, coming: int,
                                                    deleted: int) -> None:
    bags = files([10, 10, 10, 5, 5])
    assert doomed(bags, retention, coming) == bags[:deleted]


def test_only_closed_launch_bags_are_counted(tmp_path: Path) -> None:
    paths = make_bags(tmp_path, [1, 2])
    (tmp_path / 'atlas_2026-01-01-00-00-09.bag.active').write_bytes(b'x')
    (tmp_path / 'notes.bag').write_bytes(b'x')
    (tmp_path / 'atlas_dir.bag').mkdir()
    assert [bag.path for bag in bag_files(tmp_path)] == paths
    assert bag_files(tmp_path / 'missing') == []


@pytest.mark.parametrize(('env', 'expected'), [
    ({}, Retention()),
    ({'TAC_KEEP_BAGS': '', 'TAC_MAX_BAGS_MB': ''}, Retention()),
    ({'TAC_KEEP_BAGS': '5', 'TAC_MAX_BAGS_MB': '2000'}, Retention(5, 2000 * MB)),
])
def test_the_setting_comes_from_the_environment(env: dict[str, str],
                                                expected: Retention) -> None:
    assert retention_from_env(env) == expected


def test_a_bad_setting_is_one_line_and_records_nothing(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(RetentionError):
        retention_from_env({'TAC_KEEP_BAGS': '-1'})
    make_bags(tmp_path, [1])
    monkeypatch.setenv('TAC_MAX_BAGS_MB', '2GB')
    assert bag_housekeeping.main(['launch', str(tmp_path)]) == 2
    assert capsys.readouterr().err == (
        "record_run.sh: error: TAC_MAX_BAGS_MB must be a whole number >= 0 (0: no limit), "
        "got '2GB'; not recording\n")
    assert len(bag_files(tmp_path)) == 1


def test_the_launch_says_what_the_directory_holds_and_what_it_deleted(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    paths = make_bags(tmp_path, [30, 20, 10])
    monkeypatch.delenv('TAC_KEEP_BAGS', raising=False)
    monkeypatch.delenv('TAC_MAX_BAGS_MB', raising=False)
    assert bag_housekeeping.main(['launch', str(tmp_path)]) == 0
    assert capsys.readouterr().out == (
        f'record_run.sh: bag directory {tmp_path}: 3 bags, 60 MB (keep_bags:= or '
        'max_bags_mb:= limit it; make clean-bags empties it)\n')
    monkeypatch.setenv('TAC_KEEP_BAGS', '2')
    assert bag_housekeeping.main(['launch', str(tmp_path)]) == 0
    assert capsys.readouterr().out == (
        f'record_run.sh: bag directory {tmp_path}: 3 bags, 60 MB\n'
        f'record_run.sh: deleted 2 old bags (50 MB) in {tmp_path} to keep keep_bags=2 '
        "(counting this run's)\n")
    assert [bag.path for bag in bag_files(tmp_path)] == paths[2:]


@pytest.mark.parametrize(('keep', 'left'), [(0, 0), (2, 2), (9, 3)])
def test_clean_bags_deletes_all_but_the_newest_keep(
        keep: int, left: int, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    paths = make_bags(tmp_path, [30, 20, 10])
    active = tmp_path / 'atlas_2026-01-01-00-00-09.bag.active'
    active.write_bytes(b'x')
    assert bag_housekeeping.main(['clean', str(tmp_path), '--keep', str(keep)]) == 0
    assert [bag.path for bag in bag_files(tmp_path)] == paths[len(paths) - left:]
    assert active.exists(), 'a recording in progress is never deleted'
    freed = sum([30, 20, 10][:len(paths) - left])
    kept = 60 - freed
    assert capsys.readouterr().out == (f'deleted {bags_count(3 - left)} ({freed} MB) in '
                                       f'{tmp_path}; {bags_count(left)}, {kept} MB left\n')


def test_clean_bags_defaults_to_the_launchs_bag_dir(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    make_bags(tmp_path, [1])
    monkeypatch.setenv('TAC_BAG_DIR', str(tmp_path))
    assert bag_housekeeping.main(['clean']) == 0
    assert bag_files(tmp_path) == []
    assert capsys.readouterr().out == f'deleted 1 bag (1 MB) in {tmp_path}; 0 bags, 0 MB left\n'
