"""The /atlas/sim_config schema: what re-creates a run offline, as one JSON object.

The simulator node publishes it (latched, at start and after every reset), offline runs
write it into their bags, and replay reads it back. It is written and parsed here only,
so the keys and their order are stated once; bags stay bit-exact because `to_json` gives
the text the simulator has always published.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['REQUIRED_KEYS', 'SimConfig', 'SimConfigError', 'parse_sim_config']

#: The keys a config needs to be replayed (model_file and model_sha1 may be missing).
REQUIRED_KEYS = ('timestep', 'time_to_unpin', 'last_reset_time')
#: The start-up mode when the config does not say (/atlas/startup_mode unset): written only
#: when another was chosen, so that the text of a default run stays what it always was.
DEFAULT_STARTUP_MODE = 'pinned_with_gravity'


class SimConfigError(AtlasControlError):
    """A /atlas/sim_config text is not a config; the message says what is wrong with it."""


@dataclass(frozen=True)
class SimConfig:
    """The simulator's config (times in s).

    `recorded` is not on the wire: False marks defaults assumed for a bag that has no
    config (recorded before the simulator published one). `mud_damping` (N s/m) is written
    only by a simulator whose world has mud (None: none), so other runs' text is unchanged.
    """

    model_file: str | None
    model_sha1: str | None
    timestep_s: float | None
    time_to_unpin_s: float
    last_reset_time_s: float
    recorded: bool = True
    startup_mode: str = DEFAULT_STARTUP_MODE
    #: Where the robot starts (course.parse_start's text; '': the model's spawn pose at
    #: the origin), written only when given.
    start: str = ''
    mud_damping: float | None = None
    #: The seed of the head laser's noise (~sensor_seed), written only when not 0.
    sensor_seed: int = 0

    def to_dict(self) -> dict[str, Any]:
        """The JSON object, keys in the order the simulator has always published them."""
        config = {
            'model_file': self.model_file,
            'model_sha1': self.model_sha1,
            'timestep': self.timestep_s,
            'time_to_unpin': self.time_to_unpin_s,
            'last_reset_time': self.last_reset_time_s,
        }
        if self.startup_mode != DEFAULT_STARTUP_MODE:
            config['startup_mode'] = self.startup_mode
        if self.start:
            config['start'] = self.start
        if self.mud_damping is not None:
            config['mud_damping'] = self.mud_damping
        if self.sensor_seed:
            config['sensor_seed'] = self.sensor_seed
        return config

    def to_json(self) -> str:
        """The /atlas/sim_config message text."""
        return json.dumps(self.to_dict())

    @classmethod
    def from_dict(cls, config: dict[str, Any]) -> SimConfig:
        """A config from its parsed JSON object.

        Raises:
            SimConfigError: a required key is missing or not a number.
        """
        try:
            return cls(
                model_file=str(config.get('model_file')) if config.get('model_file') else None,
                model_sha1=str(config.get('model_sha1')) if config.get('model_sha1') else None,
                timestep_s=float(config['timestep']),
                time_to_unpin_s=float(config['time_to_unpin']),
                last_reset_time_s=float(config['last_reset_time']),
                startup_mode=str(config.get('startup_mode', DEFAULT_STARTUP_MODE)),
                start=str(config.get('start', '')),
                mud_damping=(None if config.get('mud_damping') is None
                             else float(config['mud_damping'])),
                sensor_seed=int(config.get('sensor_seed', 0)))
        except (KeyError, TypeError, ValueError) as err:
            raise SimConfigError(f'lacks a valid {err} (expected JSON with '
                                 f'{", ".join(REQUIRED_KEYS)}).') from None

    @classmethod
    def from_json(cls, text: str) -> SimConfig:
        """A config from its message text (see parse_sim_config and from_dict)."""
        return cls.from_dict(parse_sim_config(text))


def parse_sim_config(text: str) -> dict[str, Any]:
    """The JSON object of a /atlas/sim_config text, its keys not yet checked.

    Replay counts the resets of a bag from every config's last_reset_time, but needs only
    the last config complete, so parsing and checking the keys are two steps.

    Raises:
        SimConfigError: the text is not JSON, or not a JSON object.
    """
    try:
        config = json.loads(text)
    except json.JSONDecodeError as err:
        raise SimConfigError(f'is not JSON ({err}).') from err
    if not isinstance(config, dict):
        raise SimConfigError(f'is not a JSON object: {text!r}.')
    return config
