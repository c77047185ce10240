// BulletBoxWorld: builds a BoxScene in Bullet the way Bullet's own demos do (DBVT
// broadphase, sequential impulse solver with its defaults: 10 iterations, split impulse).
#include "bullet_world.hpp"

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <vector>

namespace spindle::bench {

namespace {

btVector3 to_bt(const Vec3& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }

btScalar geometric_mean_friction(const btCollisionObject* a, const btCollisionObject* b) {
    return std::sqrt(a->getFriction() * b->getFriction());
}

}  // namespace

struct BulletBoxWorld::Impl {
    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher{&configuration};
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
    std::vector<std::unique_ptr<btCollisionShape>> shapes;
    std::vector<std::unique_ptr<btDefaultMotionState>> motion_states;
    std::vector<std::unique_ptr<btRigidBody>> bodies;  // [0] is the floor
    CalculateCombinedCallback saved_friction_rule = gCalculateCombinedFrictionCallback;

    btRigidBody* add(btCollisionShape* shape, const Vec3& center, btScalar mass, btScalar friction) {
        btVector3 inertia(0, 0, 0);
        if (mass > 0) shape->calculateLocalInertia(mass, inertia);
        btTransform start;
        start.setIdentity();
        start.setOrigin(to_bt(center));
        motion_states.push_back(std::make_unique<btDefaultMotionState>(start));
        btRigidBody::btRigidBodyConstructionInfo info(mass, motion_states.back().get(), shape, inertia);
        info.m_friction = friction;
        info.m_restitution = 0;
        bodies.push_back(std::make_unique<btRigidBody>(info));
        world.addRigidBody(bodies.back().get());
        return bodies.back().get();
    }

    ~Impl() {
        for (auto& body : bodies) world.removeRigidBody(body.get());
        gCalculateCombinedFrictionCallback = saved_friction_rule;
    }
};

BulletBoxWorld::BulletBoxWorld(const BoxScene& scene) : m_impl(std::make_unique<Impl>()) {
    Impl& m = *m_impl;
    gCalculateCombinedFrictionCallback = geometric_mean_friction;
    m.world.setGravity(btVector3(0, btScalar(-9.81), 0));
    const auto friction = btScalar(scene.friction);
    m.shapes.push_back(std::make_unique<btBoxShape>(to_bt(scene.floor.half_extents)));
    m.add(m.shapes.back().get(), scene.floor.center, 0, friction);
    m.bodies.reserve(scene.boxes.size() + 1);
    btCollisionShape* shared = nullptr;  // Bullet's idiom: equal boxes share one shape
    Vec3 shared_half = Vec3::Zero();
    for (const BoxSpec& box : scene.boxes) {
        if (!shared || box.half_extents != shared_half) {
            m.shapes.push_back(std::make_unique<btBoxShape>(to_bt(box.half_extents)));
            shared = m.shapes.back().get();
            shared_half = box.half_extents;
        }
        const Real mass = scene.density * 8 * box.half_extents.prod();
        btRigidBody* body = m.add(shared, box.center, btScalar(mass), friction);
        body->setActivationState(DISABLE_DEACTIVATION);
    }
}

BulletBoxWorld::~BulletBoxWorld() = default;

void BulletBoxWorld::step() { m_impl->world.stepSimulation(btScalar(1.0 / 60.0), 0); }

double BulletBoxWorld::height(std::size_t box) const {
    return double(m_impl->bodies[box + 1]->getCenterOfMassPosition().y());
}

std::size_t BulletBoxWorld::box_count() const { return m_impl->bodies.size() - 1; }

}  // namespace spindle::bench
