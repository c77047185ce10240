// Values as the API's error messages print them ("got (1, nan, 0)"), shared by the
// input checks (validation.cpp, joint_api.cpp) and the state check (stages/update.cpp).
#pragma once

#include <sstream>
#include <string>

#include <spindle/engine/math.hpp>

namespace spindle {

inline std::string number(Real value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

inline std::string vec(const Vec3& v) {
    return "(" + number(v.x()) + ", " + number(v.y()) + ", " + number(v.z()) + ")";
}

}  // namespace spindle
