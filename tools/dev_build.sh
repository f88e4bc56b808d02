#!/usr/bin/env bash
# Developer build: compiles cpp_ext/ into ngfracture/ in place, for PYTHONPATH=. runs.
# Usage: tools/dev_build.sh [python]   (the python whose ngsolve to build against)
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${1:-python3}
CMAKE_DIR=$("$PY" -c 'import ngsolve.config as c; print(c.get_cmake_dir())')
cmake -S cpp_ext -B build/dev -DNGSolve_DIR="$CMAKE_DIR" -DPython3_EXECUTABLE="$(command -v "$PY")" \
      -DCMAKE_LIBRARY_OUTPUT_DIRECTORY="$PWD/ngfracture" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/dev -j2
