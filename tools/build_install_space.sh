#!/usr/bin/env bash
# build_install_space.sh WORKSPACE PREFIX: `catkin_make install` of this package as a user
# installs it, from a bare environment (only /usr's ROS; nothing of the developer's workspace
# or virtualenv can hide a missing install rule). WORKSPACE/src links to this repository and
# its two message packages; PREFIX is emptied first, so that a file an install rule no longer
# names cannot linger there, while WORKSPACE/build keeps its objects (a rebuild compiles only
# what changed). `make setup` builds it once (tools/setup.sh); test_install_space.py rebuilds
# it, installs afresh and runs the tutorial from PREFIX. The log: WORKSPACE/catkin_make.log.
set -euo pipefail
if [ "$#" -ne 2 ]; then
  echo "usage: $0 WORKSPACE PREFIX" >&2
  exit 2
fi
repo_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)
workspace=$1 prefix=$2
# shellcheck source=tools/paths.sh
source "$repo_dir/tools/paths.sh"
mkdir -p "$workspace/src"
ln -sfn "$repo_dir" "$workspace/src/tutorial_atlas_control"
ln -sfn "$repo_dir/msg/osrf_msgs" "$workspace/src/osrf_msgs"
ln -sfn "$repo_dir/msg/atlas_msgs" "$workspace/src/atlas_msgs"
rm -rf "$prefix"
log="$workspace/catkin_make.log"
# No test targets (the roscpp test clients), which an install does not hold; catkin on
# Debian's Python, where ROS lives.
if ! (cd "$workspace" && env -i HOME="${HOME:-/tmp}" PATH=/usr/local/bin:/usr/bin:/bin \
        LANG="${LANG:-C.UTF-8}" \
        catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
        "-DTAC_MUJOCO_PYTHON=$TAC_VENV/bin/python" -DCATKIN_ENABLE_TESTING=OFF \
        "-DCMAKE_INSTALL_PREFIX=$prefix" install) > "$log" 2>&1; then
  tail -40 "$log" >&2
  echo "build_install_space.sh: catkin_make install failed; full log: $log" >&2
  exit 1
fi
