#!/usr/bin/env bash
# Installs dependencies, builds Plano and runs the main job on meshes it generates itself:
# planar-quad subdivision of a cube imitating Catmull-Clark (projective maps, paper 1),
# planarization of a twisted grid, and a handle deformation that keeps every face planar.
# Results land in demo-output/ with a JSON report per step.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
BUILD_DIR=${PLANO_BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target plano
plano="$BUILD_DIR/plano"
out=demo-output
mkdir -p "$out"

echo "== planar-quad subdivision of a cube (3 Catmull-Clark levels)"
"$plano" generate cube -o "$out/cube.obj"
"$plano" subdivide "$out/cube.obj" -o "$out/cube-pq3.obj" --scheme catmull-clark --levels 3 --report "$out/subdivide.json"
"$plano" info "$out/cube-pq3.obj"

echo "== planarization of a twisted (hyperbolic paraboloid) grid"
"$plano" generate hypar -n 16 -o "$out/hypar.obj"
"$plano" planarize "$out/hypar.obj" -o "$out/hypar-planar.obj" --tolerance 0.1 --report "$out/planarize.json"

echo "== as-rigid-as-possible handle deformation of a planar-quad translational surface"
"$plano" generate translational -n 10 -o "$out/grid.obj"
# Fix the first row (vertices 0..10) and lift the far corner (vertex 120, at (1, 1, 0)) by 0.3.
cat > "$out/constraints.json" <<'JSON'
{"fixed": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10], "handles": [{"vertex": 120, "position": [1.0, 1.0, 0.3]}]}
JSON
"$plano" deform "$out/grid.obj" --constraints "$out/constraints.json" -o "$out/grid-deformed.obj" --report "$out/deform.json"
"$plano" info "$out/grid-deformed.obj"
echo "== done: meshes and reports in $out/"
