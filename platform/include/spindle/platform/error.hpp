// spindle::Error: the one exception type the public API throws for bad input.
// The message names what was wrong and, for config files, file:line:column.
#pragma once

#include <stdexcept>
#include <string>

namespace spindle {

class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace spindle
