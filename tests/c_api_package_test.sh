#!/usr/bin/env bash
# The C API from the installed package (docs/cpp.md, "The C API"), as a C programmer meets it:
# `cmake --install` of this build into a temporary prefix; libatrous.so exports the atrous*
# functions and nothing else; tests/capi/c_denoise.c compiled as strict C99 against the installed
# <atrous/atrous.h> alone and linked to the installed libatrous.so with -latrous; run, it compares
# its output with the installed CLI's and checks the bad-input errors (the file says what). Nothing
# goes into the source tree.
#
#   c_api_package_test.sh BUILD_DIR SOURCE_DIR CMAKE_COMMAND C_COMPILER
set -euo pipefail
build=$1 src=$2 cmake=$3 cc=$4

. "$(dirname "$0")/package_test_lib.sh"
install_package c_api_package_test "$build" "$cmake"
[ -e "$prefix/include/atrous/atrous.h" ] || fail "include/atrous/atrous.h was not installed"
lib=$(find "$prefix" -name 'libatrous.so' | head -n 1)
[ -n "$lib" ] || fail "no libatrous.so under the prefix"
libdir=$(dirname "$lib")

step "libatrous.so exports atrous* symbols only"
nm -D --defined-only "$lib" | awk '{ print $NF }' | sort > "$tmp/exports.txt"
others=$(grep -v '^atrous' "$tmp/exports.txt" || true)
[ -z "$others" ] || fail "libatrous.so exports other symbols: $(echo "$others" | head -n 20 | tr '\n' ' ')"
for f in atrousNewDevice atrousGetDeviceError atrousNewFilter atrousSetFilterImage atrousSetFilterInt \
         atrousSetFilterFloat atrousSetFilterBool atrousCommitFilter atrousExecuteFilter atrousReleaseFilter \
         atrousReleaseDevice; do
  grep -qx "$f" "$tmp/exports.txt" || fail "libatrous.so does not export $f"
done
echo "$(wc -l < "$tmp/exports.txt") symbols, all atrous*"

step "compile tests/capi/c_denoise.c as C99 against the installed header, link -latrous"
"$cc" -std=c99 -Wall -Wextra -pedantic -Werror -I"$prefix/include" "$src/tests/capi/c_denoise.c" \
  -L"$libdir" -latrous -Wl,-rpath,"$libdir" -lm -o "$tmp/c_denoise" 2> "$tmp/cc.log" ||
  { cat "$tmp/cc.log"; fail "compiling c_denoise.c"; }
# (ldd's output in a variable first: under pipefail, `ldd | grep -q` fails whenever grep exits at its
# first match before ldd has written everything, and ldd dies of SIGPIPE: this test's flakiness.)
deps=$(ldd "$tmp/c_denoise")
grep -q "$libdir/libatrous.so" <<< "$deps" || fail "c_denoise is not linked to the installed libatrous.so: $deps"

step "run it against the installed CLI"
mkdir "$tmp/work"
"$tmp/c_denoise" "$prefix/bin/atrous" "$tmp/work" || fail "c_denoise failed"
echo "c_api_package_test: OK"
