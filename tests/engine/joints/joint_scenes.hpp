// Small scenes the joint tests share: anchors, spheres, hanging chains, and the
// largest joint error of a set of joints.
#pragma once

#include <spindle/engine/space.hpp>

#include <algorithm>
#include <vector>

namespace spindle::test {

constexpr double kG = 9.81;         // gravity's magnitude, m/s^2, as SpaceSettings has it
constexpr double kDt = 1.0 / 60.0;  // the default step

inline BodyHandle add_static(Space& space, const Vec3& p, Real radius = 0.05) {
    BodyDesc d;
    d.type = MotionType::Static;
    d.shape = Shape::sphere(radius);
    d.position = p;
    return space.create_body(d);
}

inline BodyHandle add_dynamic(Space& space, const Shape& shape, const Vec3& p, Real mass) {
    BodyDesc d;
    d.shape = shape;
    d.position = p;
    d.mass = mass;
    return space.create_body(d);
}

inline BodyHandle add_sphere(Space& space, const Vec3& p, Real radius, Real mass) {
    return add_dynamic(space, Shape::sphere(radius), p, mass);
}

inline BodyHandle add_box(Space& space, const Vec3& p, const Vec3& half_extents, Real mass) {
    return add_dynamic(space, Shape::box(half_extents), p, mass);
}

struct Chain {
    std::vector<BodyHandle> links;
    std::vector<JointHandle> joints;
};

// A chain hung from a static anchor at `top`: `links` bars of length `spacing` along
// `direction`, joined end to end by ball-socket joints; with end_mass > 0, a ball of
// that mass hangs from the last bar.
inline Chain make_chain(Space& space, const Vec3& top, const Vec3& direction, int links, Real spacing, Real link_mass,
                        Real end_mass = 0, bool gyroscopic = false) {
    Chain chain;
    const Quat along = Quat::FromTwoVectors(Vec3::UnitX(), direction);
    BodyHandle previous = add_static(space, top);
    auto attach = [&](const BodyHandle body, const Vec3& anchor) {
        chain.joints.push_back(space.create_joint(JointDesc::ball_socket_at(previous, body, anchor)));
        chain.links.push_back(body);
        previous = body;
    };
    for (int i = 0; i < links; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(spacing / 2, 0.02, 0.02));
        d.position = top + direction * (spacing * (i + 0.5));
        d.orientation = along;
        d.mass = link_mass;
        d.gyroscopic = gyroscopic;
        attach(space.create_body(d), top + direction * (spacing * i));
    }
    if (end_mass > 0) {
        const Real radius = 0.1;
        attach(add_sphere(space, top + direction * (spacing * links + radius), radius, end_mass),
               top + direction * (spacing * links));
    }
    return chain;
}

inline Real max_linear_error(const Space& space, const std::vector<JointHandle>& joints) {
    Real worst = 0;
    for (JointHandle j : joints) worst = std::max(worst, space.internal_joint_error(j).linear);
    return worst;
}

}  // namespace spindle::test
