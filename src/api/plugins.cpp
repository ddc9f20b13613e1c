// loadPlugin (include/atrous/plugins.h): a shared library whose entry point registers methods
// (registerDenoiseMethod) into this process's registry.
#include "atrous/plugins.h"

#include <dlfcn.h>

#include <exception>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>

#include "atrous/denoise.h"
#include "atrous/error.h"

namespace atrous {

void loadPlugin(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(path + ": no such plugin file");
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": is not a file (a plugin is a shared library)");
    static std::mutex mutex;
    static std::set<std::string> loaded;
    const std::lock_guard<std::mutex> lock(mutex);
    const std::string key = std::filesystem::canonical(path, ec).string();
    if (loaded.count(key)) return;
    // The plugin's references to the library must bind to this copy of it (its registry): the
    // object that holds it (an executable linked with its symbols exported, or a module such as
    // Python's, loaded with local symbols) is made global first.
    Dl_info self{};
    if (dladdr(reinterpret_cast<void*>(&registerDenoiseMethod), &self) && self.dli_fname)
        dlopen(self.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_GLOBAL);
    dlerror();
    void* lib = dlopen(key.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        const char* why = dlerror();
        throw InputError(path + ": cannot load the plugin (" + (why ? why : "unknown error") + ")");
    }
    using Entry = void (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(lib, kPluginEntry));
    if (!entry) throw InputError(path + ": not an atrous plugin (no " + kPluginEntry + " function)");
    try {
        entry();
    } catch (const InputError& e) {  // registerDenoiseMethod's (a taken name), named after the file
        throw InputError(path + ": " + e.what());
    } catch (const std::exception& e) {
        throw RuntimeError(path + ": " + e.what());
    } catch (...) {
        throw RuntimeError(path + ": its " + kPluginEntry + " threw something that is not a std::exception");
    }
    loaded.insert(key);
}

}  // namespace atrous
