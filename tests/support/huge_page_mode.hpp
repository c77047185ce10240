// The system's transparent huge page setting, for tests whose arrays ask for huge pages
// (memory/huge_page_vector.hpp).
#pragma once

#include <fstream>
#include <string>

namespace spindle::test {

// The bracketed word of the system's transparent huge page setting ("always", "madvise",
// "never"), or "" where there is none.
inline std::string huge_page_mode() {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string text;
    std::getline(in, text);
    const auto open = text.find('[');
    const auto close = text.find(']');
    return open != std::string::npos && close > open ? text.substr(open + 1, close - open - 1) : "";
}

}  // namespace spindle::test
