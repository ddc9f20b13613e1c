# Sourced by the tests of the installed package (cpp_package_test.sh, c_api_package_test.sh,
# plugin_package_test.sh): `install_package NAME BUILD_DIR CMAKE_COMMAND` makes a temporary
# directory $tmp (removed at exit) and runs `cmake --install` of the build into $prefix=$tmp/prefix;
# fail and step print as NAME.

fail() { echo "$package_test: FAIL: $*" >&2; exit 1; }
step() { echo "== $*"; }

install_package() {
  package_test=$1
  tmp=$(mktemp -d "${TMPDIR:-/tmp}/atrous_$1.XXXXXX")
  trap 'rm -rf "$tmp"' EXIT
  prefix=$tmp/prefix
  step "install into $prefix"
  "$3" --install "$2" --prefix "$prefix" > "$tmp/install.log" || { cat "$tmp/install.log"; fail "cmake --install"; }
}
