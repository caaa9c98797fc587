#!/usr/bin/env bash
# Build and install vamp-planner from its PyPI source package into bench/peers/.venv on a
# machine that reaches PyPI and Debian but not GitHub. VAMP's CMake fetches CPM.cmake, nanobind,
# nigh, pdqsort and SIMDxorshift from GitHub; FetchInitCPM.cmake here replaces that (see its
# header), and robot_helper.hh is patched so the SIMDxorshift sampler is left out.
# Only the UR5 robot module is compiled (VAMP_ROBOT_MODULES=ur5) to save build time.
#
#   apt-get install -y libeigen3-dev pdqsort-dev
#   bash bench/peers/vamp_offline/build.sh          # ~3 min on 2 cores (UR5 module only)
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
VENV=${VENV:-$HERE/../.venv}
VERSION=${VAMP_VERSION:-0.6.4}
JOBS=${JOBS:-2}

for f in /usr/include/eigen3/Eigen/Dense /usr/include/pdqsort.h; do
  [ -e "$f" ] || { echo "missing $f: apt-get install -y libeigen3-dev pdqsort-dev" >&2; exit 1; }
done

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
"$VENV/bin/pip" download --no-deps --no-binary vamp-planner "vamp-planner==$VERSION" -d "$WORK"
tar xzf "$WORK"/vamp*planner-"$VERSION".tar.gz -C "$WORK"
SRC=$(ls -d "$WORK"/vamp*planner-"$VERSION")

cp "$HERE/FetchInitCPM.cmake" "$SRC/cmake/FetchInitCPM.cmake"
mkdir -p "$SRC/cellplan_offline"
cp -r "$HERE/nigh" "$SRC/cellplan_offline/"
HELPER="$SRC/src/impl/vamp/bindings/python/robot_helper.hh"
sed -i 's/^#if defined(__x86_64__)$/#if defined(__x86_64__) \&\& defined(VAMP_CELLPLAN_HAVE_SIMDXORSHIFT)/' "$HELPER"
[ "$(grep -c VAMP_CELLPLAN_HAVE_SIMDXORSHIFT "$HELPER")" = 2 ] || { echo "robot_helper.hh patch did not apply" >&2; exit 1; }

# Build requirements in the venv (pinned in requirements-vamp-build.txt), no build isolation,
# so the nanobind version is the one pinned there.
"$VENV/bin/pip" install -r "$HERE/requirements-vamp-build.txt"
CMAKE_BUILD_PARALLEL_LEVEL=$JOBS "$VENV/bin/pip" install --no-deps --no-build-isolation -v "$SRC" \
  --config-settings=cmake.define.VAMP_ROBOT_MODULES=ur5 \
  --config-settings=cmake.define.VAMP_ROBOT_STRUCTS=UR5
"$VENV/bin/python" -c "import vamp; print('vamp', vamp.robots)"
