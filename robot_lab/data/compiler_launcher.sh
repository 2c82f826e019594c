#!/bin/sh
# CMake's compiler launcher for builds in robot_lab's environment (robot_lab/compiler_cache.py):
#   /bin/sh compiler_launcher.sh CCACHE COMPILER ARGS...
# ccache with its base_dir at the colcon workspace being built (the folder above build/), so
# paths inside the workspace hash as relative ones and the same package built in another
# folder is a cache hit. If CCACHE is gone since CMake configured the folder, the compiler
# runs by itself.
ccache=$1
shift
[ -x "$ccache" ] || exec "$@"
if [ -z "${CCACHE_BASEDIR:-}" ]; then
  case $PWD in
    */build/*) CCACHE_BASEDIR=${PWD%/build/*}; export CCACHE_BASEDIR ;;
  esac
fi
exec "$ccache" "$@"
