#!/usr/bin/env bash
# Records an Atlas run (started by atlas.launch when record:=true).
# usage: record_run.sh BAG_DIR [atlas_recorder|rosbag]
# Records the simulator's topics, the commands and modes, and /rosout to
# BAG_DIR/atlas_<date-time>.bag; SIGINT (Ctrl-C) closes and indexes the bag.
# atlas_recorder (default): the package's recorder, which never drops a message that arrived;
# rosbag: Debian's `rosbag record`, which drops the oldest past 100 queued messages per topic.
set -euo pipefail
# roslaunch appends __name:=... and __log:=...; they go to the recorder, not to the arguments.
args=() ros_args=()
for arg in "$@"; do
  case $arg in *:=*) ros_args+=("$arg") ;; *) args+=("$arg") ;; esac
done
set -- "${args[@]}"
if [ $# -lt 1 ] || [ $# -gt 2 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
  sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'
  [ $# -ge 1 ] && [ "$1" = "-h" -o "$1" = "--help" ] && exit 0 || exit 1
fi
bag_dir=$1
recorder=${2:-atlas_recorder}
case $recorder in
  atlas_recorder|rosbag) ;;
  *) echo "record_run.sh: unknown recorder '$recorder' (expected atlas_recorder or rosbag)" >&2; exit 1 ;;
esac
mkdir -p "$bag_dir" || { echo "record_run.sh: cannot create bag directory $bag_dir" >&2; exit 1; }
TOPICS=(
  /clock /atlas/joint_states /ground_truth_odom /atlas/imu /atlas/l_foot_contact
  /atlas/r_foot_contact /atlas/joint_commands /atlas/control_mode /atlas/sim_config /rosout /tf
)
echo "record_run.sh: recording to $bag_dir/atlas_<date-time>.bag with $recorder"
# exec: roslaunch's SIGINT must reach the recorder itself so that it closes the bag.
case $recorder in
  atlas_recorder)
    # Niceness 10: when the CPU is short, the simulator's real-time pace comes first; the
    # recorder's queues hold what it has not written yet, and it catches up afterwards.
    exec nice -n 10 rosrun tutorial_atlas_control atlas_recorder "$bag_dir/atlas" "${TOPICS[@]}" __name:=recorder "${ros_args[@]}" ;;
  rosbag)
    exec rosrun rosbag record --tcpnodelay -o "$bag_dir/atlas" "${TOPICS[@]}" __name:=recorder "${ros_args[@]}" ;;
esac
