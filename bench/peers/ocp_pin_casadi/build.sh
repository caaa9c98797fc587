#!/usr/bin/env bash
# Builds pin_casadi_mv (Pinocchio's crba / potential / kinetic energy on casadi::SX) into
# bench/peers/ocp_pin_casadi/build/, against the headers and libraries that PyPI `pin` and
# `casadi` install into the venv (no other download). ~1.5 min, ~1 GB of memory, g++ >= 10.
# ocp_casadi.py runs this by itself when the binary is missing or older than the source.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
py="${PYTHON:-$here/../.venv/bin/python}"
sp="$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
cm="$sp/cmeel.prefix"
ca="$sp/casadi"
for f in "$cm/include/pinocchio/autodiff/casadi.hpp" "$ca/include/casadi/casadi.hpp" "$ca/include/eigen3/Eigen/Core"; do
    [ -e "$f" ] || { echo "build.sh: missing $f (pip install -r bench/peers/requirements.txt)" >&2; exit 1; }
done
mkdir -p "$here/build"
# The compile definitions are those of Pinocchio's exported CMake target (pinocchio's
# boost::variant of joint models needs the larger MPL limits).
g++ -O2 -std=c++17 -w \
    -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 \
    -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12 \
    -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION \
    -I"$cm/include" -I"$ca/include" -I"$ca/include/eigen3" \
    "$here/pin_casadi_mv.cpp" -o "$here/build/pin_casadi_mv.tmp" \
    -L"$cm/lib" -L"$ca" -lpinocchio_default -lcasadi -lboost_serialization \
    -Wl,-rpath,"$cm/lib" -Wl,-rpath,"$ca"
mv "$here/build/pin_casadi_mv.tmp" "$here/build/pin_casadi_mv"
echo "built $here/build/pin_casadi_mv"
