#!/usr/bin/env bash
# The ctest test `packaging`: hila as a user gets it. Installs the build into a fresh prefix,
# builds this folder's project against it (find_package(hila CONFIG), hila::online), builds a
# small cabinet database with the installed `hila build` and its installed cell and product, and
# runs plan_one_board (the README's example) on it for the installed nominal scene.
#
# Usage: run.sh HILA_BUILD_DIR WORK_DIR [CMAKE_ARGS...]
#   CMAKE_ARGS configure the project here like hila's build (compiler, build type, flags, so a
#   sanitizer build links).
set -euo pipefail

build_dir="$1"
work="$2"
shift 2
here="$(cd "$(dirname "$0")" && pwd)"
prefix="$work/prefix"

rm -rf "$work"
mkdir -p "$work"

echo "== install $build_dir into $prefix"
cmake --install "$build_dir" --prefix "$prefix" >"$work/install.log"

# The installed headers are the public ones: none includes a private dependency's headers.
if grep -rlE '#include <(fcl|ompl|CGAL|sqlite3|assimp|urdf|cholmod|tiny_gltf)' "$prefix/include"; then
  echo "FAIL: installed headers above include a private dependency's headers" >&2
  exit 1
fi

echo "== configure and build tests/packaging against it"
cmake -S "$here" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" "$@" >"$work/configure.log" ||
  { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" -j2

# The installed command defaults to the installed cell, not the source tree's.
hila="$prefix/bin/hila"
data="$prefix/share/hila/meshes"
if ! "$hila" build --help | grep -qF "$data/cell/cell.yaml"; then
  echo "FAIL: the installed hila's default cell is not $data/cell/cell.yaml:" >&2
  "$hila" build --help | grep -F cell.yaml >&2
  exit 1
fi

echo "== a small cabinet database with the installed hila build"
# Small settings (as tests/util/quick_build.hpp): seconds, not minutes.
status=0
"$hila" build "$data/cabinet/product.yaml" -o "$work/cabinet.hila" --seed 7 --jobs 2 \
  --comfort-samples 20000 --handover-candidates 60 --roadmap-nodes 300 || status=$?
# 1: some board has no handover goal with these settings; the database is still written.
if [ "$status" -gt 1 ]; then
  echo "FAIL: hila build exited $status" >&2
  exit 1
fi

echo "== plan_one_board"
out="$("$work/build/plan_one_board" "$work/cabinet.hila" "$data/cabinet/scene.yaml")"
echo "$out"
grep -q '^base: solved' <<<"$out"
echo "packaging: OK"
