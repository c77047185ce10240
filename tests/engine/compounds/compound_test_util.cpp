#include "compound_test_util.hpp"

#include <spindle/platform/error.hpp>

#include <vector>

namespace spindle::test {

Shape dumbbell() {
    const CompoundPart parts[] = {
        {Shape::sphere(kBell), Vec3(-kBellOffset, 0, 0), Quat::Identity()},
        {Shape::sphere(kBell), Vec3(kBellOffset, 0, 0), Quat::Identity()},
        {Shape::capsule(kBellOffset / 2, 0.08), Vec3::Zero(), Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()))},
    };
    return Shape::compound(parts);
}

Shape table() {
    std::vector<CompoundPart> parts;
    parts.push_back({Shape::box(kTopHalf), Vec3(0, kTableHeight - kTopHalf.y(), 0), Quat::Identity()});
    for (const Real x : {-kLegX, kLegX}) {
        for (const Real z : {-kLegZ, kLegZ})
            parts.push_back({Shape::box(kLegHalf), Vec3(x, kLegHalf.y(), z), Quat::Identity()});
    }
    return Shape::compound(parts);
}

std::string error_of(const std::function<void()>& call) {
    try {
        call();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace spindle::test
