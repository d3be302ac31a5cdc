#!/usr/bin/env bash
# Records an Atlas run with real `rosbag record` (started by atlas.launch when record:=true).
# usage: record_run.sh BAG_DIR [rosbag record options...]
# Creates BAG_DIR, then records the simulator's topics, the commands and modes, and /rosout
# to BAG_DIR/atlas_<date-time>.bag. rosbag closes and indexes the bag on SIGINT (Ctrl-C).
set -euo pipefail
if [ $# -lt 1 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
  sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'
  [ $# -ge 1 ] && exit 0 || exit 1
fi
bag_dir=$1; shift
mkdir -p "$bag_dir" || { echo "record_run.sh: cannot create bag directory $bag_dir" >&2; exit 1; }
TOPICS=(
  /clock /atlas/joint_states /ground_truth_odom /atlas/imu /atlas/l_foot_contact
  /atlas/r_foot_contact /atlas/joint_commands /atlas/control_mode /atlas/sim_config /rosout
)
echo "record_run.sh: recording to $bag_dir/atlas_<date-time>.bag"
# exec: roslaunch's SIGINT must reach rosbag itself so that it closes the bag.
exec rosrun rosbag record --tcpnodelay -o "$bag_dir/atlas" "$@" "${TOPICS[@]}" __name:=recorder
