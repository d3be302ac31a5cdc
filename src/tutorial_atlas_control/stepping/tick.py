"""One 1 ms tick in its order, written once: the node's loop and the offline runs call it.

(1) inputs: the controller's before_step (the commands that arrived since the last step, or
a controller's own command); (2) behaviour and physics: sim.step(), which computes the
acting behaviour's torque inside; (3) the state: the caller's callback counts the step and
publishes (or records) what is due, the AtlasSimInterface's state included, and the
course's scoring, if the world is scored, takes the step (course_scoring.py); (4) the end of
the step: the interface's end_step, its handover (Walk to Stand once a walk has ended,
Freeze for a fallen robot), after the state so that the state sent is the step's and a
switch shows in the next one, as DRCSim's plugin does; recorded bags depend on this order.
"""

from __future__ import annotations

from collections.abc import Callable

from tutorial_atlas_control.sim import AtlasSimulator, PhysicsDivergenceError
from tutorial_atlas_control.stepping.controller import StepController

__all__ = ['Tick']


class Tick:
    """One step of the simulator with its inputs before and its state and handover after.

    Args:
        controller: gives the simulator the coming step's command (StepController).
        publish: after the step (or a recovered divergence): count it and publish or record
            its state.
        end_step: the end of the step, after its state: the AtlasSimInterface's end_step,
            or an offline run's hook; None: nothing.
        recover: on a diverged physics, True to go on (the robot was reset; its state is
            published), False to stop (DivergenceRecovery.recover); None: the
            PhysicsDivergenceError propagates.
        score: after the state, the course's scoring of the step (CourseScoring); None:
            the world is not scored.
    """

    def __init__(self, sim: AtlasSimulator, controller: StepController,
                 publish: Callable[[], None], end_step: Callable[[], None] | None = None,
                 recover: Callable[[PhysicsDivergenceError], bool] | None = None,
                 score: Callable[[], None] | None = None) -> None:
        self.sim = sim
        self.controller = controller
        self.publish = publish
        self.end_step = end_step
        self.recover = recover
        self.score = score

    def __call__(self) -> bool:
        """One tick; False when the physics diverged and recovery gave up (then nothing was
        published and the interface's step not ended)."""
        self.controller.before_step()
        try:
            self.sim.step()
        except PhysicsDivergenceError as err:
            if self.recover is None:
                raise
            if not self.recover(err):
                return False
        self.publish()
        if self.score is not None:
            self.score()
        if self.end_step is not None:
            self.end_step()
        return True
