// A pile of compounds (dumbbells and tables) with boxes, on a plane and a static table:
// the same state, bit for bit, on 1 to 4 workers.
#include <spindle/engine/space.hpp>
#include <spindle/scheduler/single_threaded.hpp>

#include <gtest/gtest.h>

#include "compound_test_util.hpp"
#include "work_stealing_jobs.hpp"

namespace spindle {
namespace {

using namespace test;

#ifdef NDEBUG
constexpr int kSteps = 240;
#else
constexpr int kSteps = 90;
#endif

std::uint64_t run_compound_scene(JobSystem& jobs) {
    Space space(SpaceSettings{}, &jobs);
    BodyDesc d;
    d.type = MotionType::Static;
    d.shape = Shape::plane(Vec3::UnitY(), 0);
    space.create_body(d);
    d.shape = table();
    d.position = Vec3(4, 0, 0);
    space.create_body(d);
    d.type = MotionType::Dynamic;
    const Shape shapes[] = {dumbbell(), table(), Shape::box(Vec3(0.3, 0.2, 0.25))};
    int n = 0;
    for (int layer = 0; layer < 3; ++layer) {
        for (int i = 0; i < 4; ++i) {
            for (int k = 0; k < 3; ++k) {
                d.shape = shapes[n % 3];
                d.position = Vec3(i * 2.4 - 3 + 0.2 * layer, 1 + layer * 1.3, k * 2.0 - 2);
                d.orientation = Quat(Eigen::AngleAxisd(0.4 * n, Vec3(1, 2, 3).normalized()));
                space.create_body(d);
                ++n;
            }
        }
    }
    for (int i = 0; i < kSteps; ++i) space.update();
    return space.state_hash();
}

TEST(CompoundDeterminism, PileHashIsTheSameForOneToFourWorkers) {
    const std::uint64_t reference = [] {
        SingleThreadedJobSystem single;
        return run_compound_scene(single);
    }();
    for (unsigned workers : {1u, 2u, 3u, 4u}) {
        auto jobs = jobs_for(workers);
        EXPECT_EQ(run_compound_scene(*jobs), reference) << workers << " workers";
    }
}

}  // namespace
}  // namespace spindle
