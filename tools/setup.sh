#!/usr/bin/env bash
# One-command, idempotent set-up (called by `make setup`):
#   1. Debian packages (ROS 1 from Debian 12, catkin, software GL) via apt-get;
#   2. a virtualenv from /usr/bin/python3 with --system-site-packages and the pinned PyPI requirements;
#   3. a catkin workspace OUTSIDE the repository (a workspace inside the tree makes rosrun loop),
#      whose src/ holds symlinks to this package and to the vendored message packages under msg/;
#   4. beside it, an install space built as a user would (`catkin_make install`), which
#      test_install_space.py runs the tutorial from (tools/build_install_space.sh).
# Each step is skipped when its inputs have not changed since the last run, but for the catkin
# workspace's build, which make keeps current itself (build_workspace).
set -euo pipefail

repo_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)
# shellcheck source=tools/paths.sh
source "$repo_dir/tools/paths.sh"

APT_PACKAGES=(
  ros-core rosbash rosout python3-rospy python3-rostest python3-rosunit python3-rosbag
  python3-roslaunch python3-rostopic python3-rosservice python3-rosparam python3-rosmsg
  catkin catkin-lint python3-catkin-pkg python3-setuptools cmake g++ make
  ros-message-generation ros-message-runtime python3-genpy python3-gencpp python3-genmsg
  ros-std-msgs ros-sensor-msgs ros-nav-msgs ros-geometry-msgs ros-std-srvs ros-rosgraph-msgs
  python3-std-msgs python3-sensor-msgs python3-nav-msgs python3-geometry-msgs python3-std-srvs
  python3-rosgraph-msgs libstd-msgs-dev libroscpp-dev libsensor-msgs-dev libgeometry-msgs-dev
  librostest-dev librosbag-storage-dev libtopic-tools-dev python3-venv python3-yaml python3-numpy
  libosmesa6 libegl1 libopengl0 libgl1-mesa-dri
  ros-robot-state-publisher ros-tf2-msgs python3-tf2-msgs python3-tf2-ros rviz
  ros-trajectory-msgs python3-trajectory-msgs ros-visualization-msgs python3-visualization-msgs
  # What DRC-era Python clients import: tf.transformations, tf_conversions.posemath with
  # PyKDL, actionlib, roslib.load_manifest, tf2_geometry_msgs, tf2_kdl, angles; and the
  # package.xml files that let rospack, rosmsg and a client's manifest find tf,
  # tf_conversions and trajectory_msgs (Debian ships them in the -dev packages).
  python3-tf python3-tf-conversions python3-pykdl python3-actionlib python3-actionlib-msgs
  ros-actionlib-msgs libactionlib-msgs-dev python3-roslib python3-tf2-geometry-msgs python3-tf2-kdl python3-angles
  libtf-dev libtf-conversions-dev libtrajectory-msgs-dev
  xvfb xdotool x11-apps imagemagick iproute2 tmux
  python3-tk
  # The cameras: stereo_image_proc turns the pair into disparity and points2 (docs/cameras.md);
  # pluginlib finds its nodelets through the package.xml files the -dev and -tools packages hold.
  ros-stereo-image-proc libstereo-image-proc-dev libnodeletlib-tools python3-stereo-msgs
)

log() { printf 'setup: %s\n' "$*"; }

install_debian_packages() {
  local missing=() pkg
  for pkg in "${APT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' || missing+=("$pkg")
  done
  [ ${#missing[@]} -eq 0 ] && { log "Debian packages present"; return; }
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
      sudo=(sudo -n)
    else
      echo "setup: missing Debian packages: ${missing[*]}" >&2
      echo "setup: run as root or with password-less sudo, or install them with: sudo apt-get install ${missing[*]}" >&2
      exit 1
    fi
  fi
  log "installing Debian packages: ${missing[*]}"
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

create_virtualenv() {
  local stamp="$TAC_VENV/.requirements.sha1" want
  want=$(sha1sum "$repo_dir/requirements.txt" | cut -d' ' -f1)
  if [ -x "$TAC_VENV/bin/python" ] && [ "$(cat "$stamp" 2>/dev/null)" = "$want" ]; then
    log "virtualenv up to date ($TAC_VENV)"; return
  fi
  [ -x "$TAC_VENV/bin/python" ] || { log "creating virtualenv $TAC_VENV"; /usr/bin/python3 -m venv --system-site-packages "$TAC_VENV"; }
  log "installing pinned requirements"
  # Without PYTHONPATH: in a shell that sourced another clone's env.sh, pip would find the
  # requirements in that clone's virtualenv (on PYTHONPATH), install nothing here, and the
  # stamp below would call this empty virtualenv up to date.
  env -u PYTHONPATH -u VIRTUAL_ENV "$TAC_VENV/bin/python" -m pip install \
    --disable-pip-version-check -q -r "$repo_dir/requirements.txt"
  echo "$want" > "$stamp"
}

build_workspace() {
  mkdir -p "$TAC_WS/src"
  ln -sfn "$repo_dir" "$TAC_WS/src/tutorial_atlas_control"
  ln -sfn "$repo_dir/msg/osrf_msgs" "$TAC_WS/src/osrf_msgs"
  ln -sfn "$repo_dir/msg/atlas_msgs" "$TAC_WS/src/atlas_msgs"
  local stamp="$TAC_WS/.build-inputs.sha1" want
  want=$( (cd "$repo_dir" && cat CMakeLists.txt package.xml setup.py requirements.txt msg/*/CMakeLists.txt \
            msg/*/package.xml msg/*/msg/*.msg src/*.c src/*.h src/*.cpp test/rostest/*.cpp; ls scripts sim rviz test/rostest 2>/dev/null) | sha1sum | cut -d' ' -f1)
  # The build runs even when the inputs are unchanged: a new checkout of the same files (a
  # fresh clone at the same path) is newer than the build's outputs, and make would otherwise
  # regenerate the messages and relink the library later, in the rostests' catkin_make, while
  # pytest imports them beside it (a half-written message module imported nothing). Unchanged
  # and built, it does nothing in about 6 s.
  if [ -f "$TAC_WS/devel/setup.bash" ] && [ "$(cat "$stamp" 2>/dev/null)" = "$want" ]; then
    log "catkin workspace inputs unchanged; bringing its build up to date ($TAC_WS)"
  else
    log "building catkin workspace $TAC_WS"
  fi
  (
    # catkin must use Debian's Python (where ROS lives), not whatever python3 is first on PATH.
    unset PYTHONPATH CMAKE_PREFIX_PATH ROS_PACKAGE_PATH
    cd "$TAC_WS"
    # The compiled library links the virtualenv's mujoco wheel (CMakeLists.txt).
    catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
      "-DTAC_MUJOCO_PYTHON=$TAC_VENV/bin/python" -DCATKIN_ENABLE_TESTING=ON > "$TAC_WS/build.log" 2>&1 \
      || { tail -40 "$TAC_WS/build.log" >&2; echo "setup: catkin_make failed; full log: $TAC_WS/build.log" >&2; exit 1; }
  )
  echo "$want" > "$stamp"
}

build_install_space() {
  local stamp="$TAC_INSTALL_WS/.build-inputs.sha1" want
  want=$(cat "$TAC_WS/.build-inputs.sha1")
  if [ -f "$TAC_INSTALL_PREFIX/setup.bash" ] && [ "$(cat "$stamp" 2>/dev/null)" = "$want" ]; then
    log "install space up to date ($TAC_INSTALL_PREFIX)"; return
  fi
  log "building the install space $TAC_INSTALL_PREFIX (for test_install_space.py)"
  bash "$repo_dir/tools/build_install_space.sh" "$TAC_INSTALL_WS" "$TAC_INSTALL_PREFIX"
  echo "$want" > "$stamp"
}

install_debian_packages
create_virtualenv
build_workspace
build_install_space
log "done; now: source ./env.sh"
