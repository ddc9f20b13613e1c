#!/usr/bin/env bash
# A plugin from the installed package (include/atrous/plugins.h): `cmake --install` of this build into
# a temporary prefix; the toy plugin's sources (ATROUS_TOY_PLUGIN_SOURCES, tests/CMakeLists.txt)
# compiled against the installed include/atrous and nothing of src/ (the tests folder is on the path
# for the plugin's own toy_*.h only); the installed CLI loads it, lists its still and its sequence
# method and runs both.
#
#   plugin_package_test.sh BUILD_DIR SOURCE_DIR CMAKE_COMMAND CXX_COMPILER PLUGIN_SOURCE...
set -euo pipefail
build=$1 src=$2 cmake=$3 cxx=$4
shift 4
sources=("$@")
[ "${#sources[@]}" -gt 0 ] || { echo "plugin_package_test: no plugin sources given" >&2; exit 1; }

. "$(dirname "$0")/package_test_lib.sh"
install_package plugin_package_test "$build" "$cmake"
cli=$prefix/bin/atrous

step "build the plugin from the installed headers: ${sources[*]##*/}"
# No -I to src/: an include of a private header fails here. The plugin links nothing (the loading
# program provides the library).
"$cxx" -std=c++17 -O2 -fPIC -shared -DATROUS_TOY_PLUGIN=1 -I"$prefix/include" -I"$src/tests" "${sources[@]}" \
  -o "$tmp/libtoy_plugin.so" 2> "$tmp/cxx.log" || { cat "$tmp/cxx.log"; fail "building the plugin"; }
plugin=$tmp/libtoy_plugin.so

step "the installed CLI lists and runs its method"
"$cli" --plugin "$plugin" denoise --help > "$tmp/help.txt" 2>&1 || { cat "$tmp/help.txt"; fail "denoise --help with the plugin"; }
grep -q "toy: a toy" "$tmp/help.txt" || fail "denoise --help does not list the plugin's toy method"
"$cli" render --scene cornell --width 32 --height 24 --spp 4 --quiet --out "$tmp/r" > /dev/null
"$cli" --plugin "$plugin" denoise --in "$tmp/r" --method toy --out "$tmp/toy.exr" > "$tmp/run.txt" 2>&1 ||
  { cat "$tmp/run.txt"; fail "denoise --method toy"; }
cat "$tmp/run.txt"
grep -q "method toy" "$tmp/run.txt" || fail "the run does not say it ran the toy"
[ -s "$tmp/toy.exr" ] || fail "no output written"
"$cli" compare --ref "$tmp/r/color.exr" "$tmp/toy.exr" --json > "$tmp/change.json"
change=$(sed -n 's/.*"mse": *\([^,]*\),*/\1/p' "$tmp/change.json" | head -n 1)
awk -v c="$change" 'BEGIN { exit !(c > 0) }' || fail "the toy's output equals its input (MSE $change)"
step "the installed CLI lists and runs its sequence method"
grep -q "toyseq" "$tmp/help.txt" || fail "denoise --help does not list the plugin's toy sequence method"
"$cli" render --scene cornell-moving --width 32 --height 24 --spp 2 --frames 3 --quiet --out "$tmp/seq" > /dev/null
"$cli" --plugin "$plugin" denoise --sequence "$tmp/seq" --method toyseq --out "$tmp/seq-out" > "$tmp/seq.txt" 2>&1 ||
  { cat "$tmp/seq.txt"; fail "denoise --sequence --method toyseq"; }
n=$(ls "$tmp/seq-out"/frame_*.exr 2>/dev/null | wc -l)
[ "$n" -eq 3 ] || { cat "$tmp/seq.txt"; fail "toyseq wrote $n frames, not 3"; }
# Without the plugin the names are refused.
if "$cli" denoise --sequence "$tmp/seq" --method toyseq --out "$tmp/seq-none" > /dev/null 2>&1; then
  fail "the CLI without the plugin ran --method toyseq"
fi
if "$cli" denoise --in "$tmp/r" --method toy --out "$tmp/none.exr" > /dev/null 2>&1; then
  fail "the CLI without the plugin ran --method toy"
fi
echo "plugin_package_test: OK"
