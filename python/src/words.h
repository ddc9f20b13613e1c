// Python's errors name Python's keywords where the library's messages name the CLI's flags.
#pragma once
#include <cctype>
#include <initializer_list>
#include <string>
#include <utility>

namespace atrous::python {

// The library's messages about a render's files name the CLI's flags (`--in DIR`, `--pass
// BUFFER=NAME`, `--layer NAME`: io::loadBuffers, pass_map); Python's errors name Python's keywords
// instead (path, passes, layer). A flag is a whole word: "--in" followed by a letter, digit or '-'
// is another flag and stays.
inline std::string pythonWords(std::string msg, std::initializer_list<std::pair<const char*, const char*>> words) {
    for (const auto& [flag, keyword] : words) {
        const std::string f = flag;
        for (size_t at = msg.find(f); at != std::string::npos; at = msg.find(f, at)) {
            const size_t end = at + f.size();
            const bool whole = end == msg.size() || !(std::isalnum(static_cast<unsigned char>(msg[end])) || msg[end] == '-');
            if (!whole) {
                at = end;
                continue;
            }
            msg.replace(at, f.size(), keyword);
            at += std::string(keyword).size();
        }
    }
    return msg;
}

}  // namespace atrous::python
