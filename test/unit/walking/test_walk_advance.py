"""Walk's phase logic looks at a phase's end condition only once the phase may end
(PhaseSequence.may_end): at every tick of a pushed walk the phase moves on exactly when
`settled` says so on the condition observed (the swing foot touching, the capture point at
rest), as when the condition was observed at every tick."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.balance import BalanceState
from tutorial_atlas_control.walking import walk as walk_module
from tutorial_atlas_control.walking.phases import settled
from tutorial_atlas_control.walking.walk import WalkController
from tutorial_atlas_control.walking.walk_trial import pushed_walk_trial


def test_the_walk_moves_on_exactly_when_its_phase_settles(
        monkeypatch: pytest.MonkeyPatch) -> None:
    advance = WalkController._advance
    ticks, ended = [0], []

    def checked(self: WalkController, state: BalanceState, time_s: float) -> None:
        phases = self.phases
        condition = walk_module._phase_over(phases.phase, self.step, state,
                                            self.gains.at_rest_m)
        ends = not phases.done and settled(time_s - phases.started_s, phases.end.shortest_s,
                                           phases.end.longest_s, condition)
        before = (phases.phase, phases.started_s, phases.done)
        advance(self, state, time_s)
        ticks[0] += 1
        assert ((phases.phase, phases.started_s, phases.done) != before) == ends, time_s
        if ends:
            ended.append(before[0].name)

    monkeypatch.setattr(WalkController, '_advance', checked)
    trial, _ = pushed_walk_trial(5, steps=3, every_s=1.0)
    assert not trial.fell and trial.steps == 3 and ticks[0] > 3000
    assert len(ended) == 5 and ended[0] == 'sway' and ended[-1] == 'catch'
