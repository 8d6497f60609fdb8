#!/usr/bin/env bash
# Build VAMP (PyPI `vamp-planner`, KavrakiLab's SIMD motion planner) from its PyPI sdist and install it into
# .venv, without reaching GitHub: the sdist fetches CPM.cmake, nigh, pdqsort, SIMDxorshift and nanobind from
# GitHub at configure time, so those come from third_party/vamp/ (see its README.md) instead.
#
# Panda only (vamp.panda), portable: -march=x86-64-v3 (AVX2), not the sdist's default -march=native.
# Needs: x86_64 with AVX2, a C++ compiler, Debian libeigen3-dev, PyPI (the sdist and its build requirements).
# Exits non-zero with one line on stderr when it cannot; the full log is in runs/build_vamp.log.
#
# Environment: VAMP_REBUILD=1 rebuilds even when vamp already imports; PYTHON=... installs into another
# interpreter's environment; VAMP_WHEEL_DIR=dir keeps a copy of the built wheel there.
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
VERSION=0.6.4
SDIST_SHA256=d3150c6b67ff941af9ad56480b31d3fb73b12211ea21dc684f7737b059f6daba
# The sdist's build requirements (isolated build environment), pinned to the versions this was verified with.
BUILD_PINS="scikit-build-core==1.1.2 nanobind==3.1.0 cmake==4.4.5 typing_extensions==4.16.0 packaging==26.4 pathspec==1.1.1"
PY=${PYTHON:-$ROOT/.venv/bin/python}
DEPS=$ROOT/third_party/vamp
LOG=$ROOT/runs/build_vamp.log

die() {
  echo "build_vamp: $*" >&2
  exit 1
}

[ -x "$PY" ] || die "no Python at $PY (make test creates .venv)"
if [ "${VAMP_REBUILD:-0}" != 1 ] && "$PY" -c "import vamp; vamp.panda" >/dev/null 2>&1; then
  echo "build_vamp: vamp already installed in $PY (VAMP_REBUILD=1 to rebuild)"
  exit 0
fi
[ "$(uname -m)" = x86_64 ] || die "x86_64 only (SIMDxorshift and the AVX2 build); this is $(uname -m)"
grep -qw avx2 /proc/cpuinfo || die "this CPU has no AVX2, which VAMP's x86 build needs"
command -v c++ >/dev/null 2>&1 || die "no C++ compiler (c++) on PATH"
[ -f /usr/include/eigen3/Eigen/Core ] || die "Eigen3 headers missing: apt-get install libeigen3-dev"
for d in CPM.cmake nigh/src pdqsort/pdqsort.h SIMDxorshift/src nanobind/CMakeLists.txt; do
  [ -e "$DEPS/$d" ] || die "third_party/vamp/$d is missing"
done
echo 117cbf2711572f113bab262933eb5187b08cfc06dce0714a1ee94f2183ddc3ec "$DEPS/CPM.cmake" | sha256sum -c --quiet - \
  >/dev/null 2>&1 || die "third_party/vamp/CPM.cmake does not have the SHA-256 the sdist expects"

mkdir -p "$(dirname "$LOG")"
: >"$LOG"
WORK=$(mktemp -d "${TMPDIR:-/tmp}/build_vamp.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
start=$(date +%s)

echo "build_vamp: downloading the vamp-planner $VERSION sdist from PyPI" >&2
"$PY" -m pip download --disable-pip-version-check --no-deps --no-binary vamp-planner \
  "vamp-planner==$VERSION" -d "$WORK/sdist" >>"$LOG" 2>&1 \
  || die "could not download the vamp-planner $VERSION sdist from PyPI (log: runs/build_vamp.log)"
SDIST=$(ls "$WORK"/sdist/vamp_planner-"$VERSION".tar.gz 2>/dev/null) \
  || die "pip download did not leave vamp_planner-$VERSION.tar.gz (log: runs/build_vamp.log)"
echo "$SDIST_SHA256 $SDIST" | sha256sum -c --quiet - >/dev/null 2>&1 \
  || die "the downloaded vamp_planner-$VERSION.tar.gz does not have the expected SHA-256"
tr ' ' '\n' <<<"$BUILD_PINS" >"$WORK/build-constraints.txt"

# FetchInitCPM.cmake downloads CPM.cmake to <build>/cmake/CPM.cmake unless a file with the expected hash is there.
mkdir -p "$WORK/build/cmake" "$WORK/wheels"
cp "$DEPS/CPM.cmake" "$WORK/build/cmake/CPM.cmake"
export CPM_SOURCE_CACHE=$WORK/cpm-cache
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}

echo "build_vamp: building the Panda-only wheel (a few minutes)" >&2
PIP_CONSTRAINT="$WORK/build-constraints.txt" PIP_BUILD_CONSTRAINT="$WORK/build-constraints.txt" "$PY" -m pip wheel --disable-pip-version-check --no-cache-dir --no-deps -v -w "$WORK/wheels" \
  -C build-dir="$WORK/build" \
  -C cmake.define.CPM_nigh_SOURCE="$DEPS/nigh" \
  -C cmake.define.CPM_pdqsort_SOURCE="$DEPS/pdqsort" \
  -C cmake.define.CPM_SIMDxorshift_SOURCE="$DEPS/SIMDxorshift" \
  -C cmake.define.CPM_nanobind_SOURCE="$DEPS/nanobind" \
  -C cmake.define.FETCHCONTENT_FULLY_DISCONNECTED=ON \
  -C cmake.define.VAMP_ROBOT_MODULES=panda \
  -C cmake.define.VAMP_ROBOT_STRUCTS=Panda \
  -C cmake.define.VAMP_ARCH=-march=x86-64-v3 \
  "$SDIST" >>"$LOG" 2>&1 \
  || die "the wheel did not build: $(grep -m1 -E 'CMake Error|error:' "$LOG" | cut -c1-160) (log: runs/build_vamp.log)"
WHEEL=$(ls "$WORK"/wheels/vamp_planner-"$VERSION"-*.whl 2>/dev/null) || die "no wheel was written (log: runs/build_vamp.log)"

"$PY" -m pip install --disable-pip-version-check --no-deps --force-reinstall "$WHEEL" >>"$LOG" 2>&1 \
  || die "could not install $(basename "$WHEEL") (log: runs/build_vamp.log)"
"$PY" -c "import vamp; vamp.panda" >>"$LOG" 2>&1 || die "vamp installed but does not import (log: runs/build_vamp.log)"
if [ -n "${VAMP_WHEEL_DIR:-}" ]; then
  mkdir -p "$VAMP_WHEEL_DIR" && cp "$WHEEL" "$VAMP_WHEEL_DIR/"
fi
echo "build_vamp: installed $(basename "$WHEEL") into $PY in $(($(date +%s) - start)) s"
