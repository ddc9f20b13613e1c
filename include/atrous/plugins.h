// Methods from shared libraries: a plugin is a library built against include/atrous with an
// entry point `extern "C" void atrous_plugin_register()` that calls registerDenoiseMethod
// (atrous/denoise.h) or registerSequenceMethod (atrous/sequence_methods.h); loading it adds its
// methods to this process's registry, so every front-end lists and runs them (`atrous --plugin
// FILE.so ...`, Python's atrous.load_plugin, the farm's and the evaluation's --plugin). The toy
// plugin is one (tests/toy_plugin.cpp's entry point registers the toy still method and the toy
// sequence method; ATROUS_TOY_PLUGIN_SOURCES in tests/CMakeLists.txt;
// build/tests/libatrous_toy_plugin.so), built from the installed include/atrous alone by
// tests/plugin_package_test.sh: `c++ -std=c++17 -shared -fPIC -I<prefix>/include *.cpp`, linking
// nothing (the loading program provides the library). Linux (dlopen); same compiler and atrous
// version.
#pragma once
#include <string>

namespace atrous {

constexpr const char* kPluginEntry = "atrous_plugin_register";

// Loads the plugin at `path` and calls its entry point (once per process: loading it again does
// nothing). InputError naming the file when it is missing, cannot be loaded (undefined symbols,
// another architecture) or has no entry point; a method it registers under a taken name is the
// InputError of registerDenoiseMethod.
void loadPlugin(const std::string& path);

}  // namespace atrous
