// The toy plugin's entry point (include/atrous/plugins.h): one call per method the plugin holds.
// Its sources are ATROUS_TOY_PLUGIN_SOURCES (tests/CMakeLists.txt), built against the public
// headers only (tests/plugin_package_test.sh builds them from an installed atrous).
#include "toy_method.h"

extern "C" void atrous_plugin_register() {
    atrous::toy::registerToy();
    atrous::toy::registerToySequence();  // tests/toy_sequence_method.cpp
}
