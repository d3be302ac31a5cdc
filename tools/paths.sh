# Where this clone's virtualenv and catkin workspace live (sourced by tools/setup.sh and env.sh).
# Outside the repository, one directory per clone (keyed by the clone's path), so that fresh
# clones never share a half-built workspace. Override the root with TAC_CACHE_DIR.
_tac_repo=${repo_dir:?}
TAC_CACHE_DIR=${TAC_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/tutorial_atlas_control}
TAC_HOME="$TAC_CACHE_DIR/$(printf '%s' "$_tac_repo" | sha1sum | cut -c1-12)"
TAC_VENV="$TAC_HOME/venv"
TAC_WS="$TAC_HOME/ws"
# An install space as a user builds it, checked by test_install_space.py.
TAC_INSTALL_WS="$TAC_HOME/install_ws"
TAC_INSTALL_PREFIX="$TAC_HOME/install"
unset _tac_repo
