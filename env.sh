# Source this file (`source ./env.sh`) to get the project's whole ROS environment:
# the catkin workspace sourced, the project's virtualenv first on PATH, and ROS bound to
# localhost. To open ROS to a network deliberately, export ROS_HOSTNAME (or ROS_IP) and
# ROS_MASTER_URI with this machine's reachable name *before* sourcing this file.
# bash names the sourced file in BASH_SOURCE (eval: other shells refuse the syntax), zsh in
# $0; a POSIX sh names only itself, so there the current directory must be the repository.
if [ -n "${BASH_VERSION:-}" ]; then
  eval 'repo_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)'
else
  repo_dir=$(cd "$(dirname "$0")" 2>/dev/null && pwd -P)
fi
if [ ! -f "$repo_dir/tools/paths.sh" ]; then
  repo_dir=$(pwd -P)
  if [ ! -f "$repo_dir/tools/paths.sh" ]; then
    echo "env.sh: this shell does not say where env.sh is; source it from the repository's directory (. ./env.sh)" >&2
    unset repo_dir
    return 1 2>/dev/null || exit 1
  fi
fi
. "$repo_dir/tools/paths.sh"
if [ ! -f "$TAC_WS/devel/setup.sh" ] || [ ! -x "$TAC_VENV/bin/python" ]; then
  echo "env.sh: the project is not set up yet (no workspace at $TAC_WS); run \`make setup\` first" >&2
  unset repo_dir
  return 1 2>/dev/null || exit 1
fi
# catkin's setup.sh resets PYTHONPATH/CMAKE_PREFIX_PATH to the workspace chain.
if [ -n "${BASH_VERSION:-}" ]; then . "$TAC_WS/devel/setup.bash"; else . "$TAC_WS/devel/setup.sh"; fi
export VIRTUAL_ENV="$TAC_VENV"
# Nodes started by rosrun/roslaunch run under /usr/bin/python3 (catkin writes that shebang);
# the virtualenv's packages (mujoco, rosbags, ...) must be importable there too. Same Python.
_tac_site=$("$TAC_VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
case ":${PYTHONPATH:-}:" in *":$_tac_site:"*) ;; *) export PYTHONPATH="${PYTHONPATH:+$PYTHONPATH:}$_tac_site" ;; esac
unset _tac_site
case ":$PATH:" in *":$TAC_VENV/bin:"*) ;; *) export PATH="$TAC_VENV/bin:$PATH" ;; esac
# Loopback by default: rospy and the master bind to 127.0.0.1 when the host name is localhost.
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
export ROS_MASTER_URI="${ROS_MASTER_URI:-http://localhost:11311}"
# Offscreen rendering without a GPU or display: software OSMesa unless the user chose otherwise.
if [ -z "${DISPLAY:-}" ] && [ -z "${MUJOCO_GL:-}" ]; then export MUJOCO_GL=osmesa PYOPENGL_PLATFORM=osmesa; fi
export TAC_REPO_DIR="$repo_dir" TAC_HOME TAC_WS TAC_VENV TAC_INSTALL_WS TAC_INSTALL_PREFIX
unset repo_dir
# The tutorial's roscd, rosls, rosed, roscp and the ROS commands' tab completion: shell
# functions from Debian's rosbash package, for bash only (nothing else sources them).
_tac_rosbash=/usr/share/bash-completion/completions/rosbash
if [ -n "${BASH_VERSION:-}" ] && [ -f "$_tac_rosbash" ]; then
  . "$_tac_rosbash"
elif [ -n "${BASH_VERSION:-}" ]; then
  echo "env.sh: no roscd/rosls/rosed/roscp or ROS tab completion: $_tac_rosbash is missing (install Debian's rosbash: make setup)" >&2
else
  echo "env.sh: no roscd/rosls/rosed/roscp or ROS tab completion in this shell: they are bash functions (Debian's rosbash); ROS itself is set up" >&2
fi
unset _tac_rosbash
