#!/usr/bin/env bash
# Installs dependencies, builds Plano and runs the main job on a mesh it generates:
# a surface of revolution, its planarity, written out as OBJ.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
BUILD_DIR=${PLANO_BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target plano
mkdir -p demo-output
"$BUILD_DIR"/plano generate revolution -n 16 -o demo-output/revolution.obj
"$BUILD_DIR"/plano info demo-output/revolution.obj
