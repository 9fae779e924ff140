# Sourced by scripts/build.sh and scripts/package.sh: compile through ccache (cached under
# /var/cache/ccache) when it is installed. CMake takes the launcher from the environment
# (CMAKE_CXX_COMPILER_LAUNCHER) when it configures a new tree; CCACHE_BASEDIR (the source tree,
# $1) makes the paths under it relative, so that a fresh clone of mostly the same sources, as CI
# makes each run, compiles only what changed.
if command -v ccache >/dev/null; then
  export CCACHE_DIR=${CCACHE_DIR:-/var/cache/ccache} CCACHE_BASEDIR=$1 CCACHE_NOHASHDIR=1
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache
fi
