"""A long-lived rospy client the tests talk to: one process instead of one `rostopic` each.

`rostopic pub -1` latches for 3 s and `rostopic echo -n 1` starts a Python and a node per
reading; a test that publishes a dozen inputs and reads the clock between them spent most
of its time there. This node starts once per launch and answers one JSON line per request
on stdin with one JSON line on stdout:

- `{"do": "publish", "topic": T, "type": "pkg/Msg", "yaml": Y}`: Y filled in as `rostopic
  pub T pkg/Msg -- Y` fills it, published latched once every subscriber the master lists
  for T is connected (what `rostopic pub -1`'s 3 s stand for); answers `{"ok": true}`.
- `{"do": "next", "topic": T, "timeout_s": S}`: the next message on T, as the YAML mapping
  `rostopic echo -n 1 T` prints, under `"message"`.

Errors are answered as `{"error": "..."}`; the process ends at the end of its stdin.
"""

from __future__ import annotations

import json
import sys
import time
from typing import Any

import genpy
import rosgraph
import roslib.message
import rospy
import rostopic
import yaml

#: Wall seconds a publish waits for the master's subscribers to connect before it sends
#: anyway (a subscriber registered by a node that died never connects).
CONNECT_TIMEOUT_S = 20.0
CALLER_ID = '/tutorial_atlas_control_test_talker'


def subscribers_of(topic: str) -> set[str]:
    _, subscribers, _ = rosgraph.Master(CALLER_ID).getSystemState()
    return next((set(nodes) for name, nodes in subscribers if name == topic), set())


def publish(publishers: dict[str, rospy.Publisher], request: dict[str, Any]) -> dict[str, Any]:
    topic, type_name = request['topic'], request['type']
    publisher = publishers.get(topic)
    if publisher is None:
        message_class = roslib.message.get_message_class(type_name)
        if message_class is None:
            return {'error': f'unknown message type {type_name}'}
        publisher = publishers[topic] = rospy.Publisher(topic, message_class, queue_size=100,
                                                        latch=True)
    message = publisher.data_class()
    genpy.message.fill_message_args(message, [yaml.safe_load(request['yaml'])])
    deadline = time.monotonic() + CONNECT_TIMEOUT_S
    while (publisher.get_num_connections() < len(subscribers_of(topic))
           and time.monotonic() < deadline):
        time.sleep(0.01)
    publisher.publish(message)
    return {'ok': True}


def next_message(request: dict[str, Any]) -> dict[str, Any]:
    topic, timeout_s = request['topic'], float(request.get('timeout_s', 60.0))
    message_class, _, _ = rostopic.get_topic_class(topic, blocking=False)
    if message_class is None:
        return {'error': f'nothing publishes {topic}'}
    message = rospy.wait_for_message(topic, message_class, timeout=timeout_s)
    return {'message': yaml.safe_load(genpy.message.strify_message(message))}


def main() -> None:
    rospy.init_node('test_talker', anonymous=True, disable_signals=True)
    publishers: dict[str, rospy.Publisher] = {}
    for line in sys.stdin:
        request = json.loads(line)
        try:
            reply = (publish(publishers, request) if request['do'] == 'publish'
                     else next_message(request))
        except Exception as err:  # noqa: BLE001 - every failure goes back to the test
            reply = {'error': f'{type(err).__name__}: {err}'}
        print(json.dumps(reply), flush=True)


if __name__ == '__main__':
    main()
