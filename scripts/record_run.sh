#!/usr/bin/env bash
# Records an Atlas run (started by atlas.launch when record:=true).
# usage: record_run.sh BAG_DIR [atlas_recorder|rosbag [lz4|bz2|none]]
# Records the simulator's topics, the commands and modes, and /rosout to
# BAG_DIR/atlas_<date-time>.bag; SIGINT (Ctrl-C) closes and indexes the bag.
# atlas_recorder (default): the package's recorder, which never drops a message that arrived;
# rosbag: Debian's `rosbag record`, which drops the oldest past 100 queued messages per topic.
# lz4 (default), bz2, none: the bag's chunk compression (`rosbag record --lz4`, `--bz2`).
# It first says what BAG_DIR holds; $TAC_KEEP_BAGS=N / $TAC_MAX_BAGS_MB=M delete its oldest bags.
# Exit status: 1 when it cannot record, 2 on a bad command line.
set -euo pipefail
prog=record_run.sh
fail() { echo "$prog: error: $1" >&2; exit "${2:-1}"; }
# roslaunch appends __name:=... and __log:=...; they go to the recorder, not to the arguments.
args=() ros_args=()
for arg in "$@"; do
  case $arg in *:=*) ros_args+=("$arg") ;; *) args+=("$arg") ;; esac
done
set -- "${args[@]}"
if [ $# -ge 1 ] && { [ "$1" = "-h" ] || [ "$1" = "--help" ]; }; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
  exit 0
fi
[ $# -ge 1 ] && [ $# -le 3 ] || fail "expected BAG_DIR [atlas_recorder|rosbag [lz4|bz2|none]], got $# argument(s); see --help" 2
bag_dir=$1
recorder=${2:-atlas_recorder}
compression=${3:-lz4}
case $recorder in
  atlas_recorder|rosbag) ;;
  *) fail "unknown recorder '$recorder' (expected atlas_recorder or rosbag)" 2 ;;
esac
case $compression in
  lz4|bz2) rosbag_compression=(--"$compression") ;;
  none) rosbag_compression=() ;;
  *) fail "unknown compression '$compression' (expected lz4, bz2 or none)" 2 ;;
esac
# The list has one home, tutorial_atlas_control.topics, shared with the analysis and replay
# that read these bags; a copy here would drift from it.
# $TAC_RECORD_IMAGES=true (atlas.launch's record_images): the cameras' JPEG images too.
topics=$(python3 -c 'import sys; from tutorial_atlas_control.topics import RECORDED_TOPICS as R, IMAGE_RECORDED_TOPICS as I; print(*R, *(I if sys.argv[1] == "true" else ()))' "${TAC_RECORD_IMAGES:-false}" 2>/dev/null) \
  || fail "cannot import tutorial_atlas_control.topics for the topic list; source ./env.sh (or the workspace's setup.bash) first"
read -r -a TOPICS <<< "$topics"
# Another launch's recorder on this master: refuse before registering (the master would
# hand it our name and stop it), one line (tutorial_atlas_control.node.single_instance).
python3 -m tutorial_atlas_control.node.single_instance "$prog" recorder "${ros_args[@]}" || exit 1
mkdir -p "$bag_dir" || fail "cannot create bag directory $bag_dir"
# What the directory holds, and $TAC_KEEP_BAGS / $TAC_MAX_BAGS_MB's retention (off if unset).
python3 -m tutorial_atlas_control.cli.bag_housekeeping launch "$bag_dir" || exit 2
echo "$prog: recording to $bag_dir/atlas_<date-time>.bag with $recorder, chunks compressed: $compression"
# exec: roslaunch's SIGINT must reach the recorder itself so that it closes the bag.
case $recorder in
  atlas_recorder)
    # Niceness 10: when the CPU is short, the simulator's real-time pace comes first; the
    # recorder's queues hold what it has not written yet, and it catches up afterwards.
    exec nice -n 10 rosrun tutorial_atlas_control atlas_recorder --compression "$compression" "$bag_dir/atlas" "${TOPICS[@]}" __name:=recorder "${ros_args[@]}" ;;
  rosbag)
    exec rosrun rosbag record --tcpnodelay "${rosbag_compression[@]}" -o "$bag_dir/atlas" "${TOPICS[@]}" __name:=recorder "${ros_args[@]}" ;;
esac
