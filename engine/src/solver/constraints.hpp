// Solver data for one step: constraints built from the touching manifolds, and the
// colours that let each batch run in parallel without two jobs writing one body.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "solver/solver_body.hpp"
#include "solver/wide.hpp"
#include "world.hpp"

namespace spindle {

// Soft constraint coefficients (Box2D v3's soft step): a spring of `hertz` with a
// damping ratio, expressed for a substep of length h.
struct Softness {
    Real bias_rate = 0;
    Real mass_scale = 1;
    Real impulse_scale = 0;
};
Softness make_softness(Real hertz, Real damping_ratio, Real h);

// One velocity row of a single lane, for a push-out row (contact_solver.cpp): relative
// speed = dir.(vb - va) + rb_x.wb - ra_x.wa, and an impulse L changes wa by -L ia, wb by +L ib.
struct ContactRow {
    Vec3 ra_x = Vec3::Zero();  // ra x dir
    Vec3 rb_x = Vec3::Zero();  // rb x dir
    Vec3 ia = Vec3::Zero();    // Ia^-1 (ra x dir)
    Vec3 ib = Vec3::Zero();    // Ib^-1 (rb x dir)
};

// Where a lane's push-out row acts (contact_solver.cpp): the overlap's centre from each
// centre of mass, as the last push of the step found it. The row itself is made again
// from these when warm starting: the same inputs give the same bits, at half the bytes.
struct PushAnchors {
    Vec3 ra = Vec3::Zero();
    Vec3 rb = Vec3::Zero();
};

// What a WideContact keeps of a row for its lanes: the inertia-weighted angular terms.
// The row's speed is taken from the point's relative velocity instead, so ra x dir and
// rb x dir need not be stored: fewer bytes for every pass to stream.
struct WideRow {
    Wide3 ia, ib;
};

// One point slot of a WideContact's manifolds (contact_solver.cpp): what the solve passes
// read besides the row the warm start reads too (WidePointRow). A slot a manifold does not
// fill has no mass and lies far apart, so it never pushes and never rubs.
struct WidePoint {
    Wide3 ra, rb;                // anchors from each centre of mass, world, fixed for the step
    Wide adjusted_separation{};  // separation minus n.(rb - ra): current separation = n.d + this
    Wide normal_mass{};
    Wide lever_arm{};  // distance from the friction centre on A: the twist friction's reach
};

// A point slot's normal row and accumulated impulse: all the warm start reads of a point.
struct WidePointRow {
    WideRow normal_row;
    Wide normal_impulse{};
};

// Rolling resistance of a WideContact's lanes (Box3D's): an angular impulse against the
// bodies' relative spin, within the cap x the manifold's normal impulse. Kept apart from the
// wide contacts (one per wide contact, SolverScratch::rolling) and written only for those
// whose `rolls` is set: the passes of a scene without it stream none of these bytes.
struct WideRolling {
    Wide cap{};                             // per unit normal impulse: the mixed coefficient x the rolling radius
    WideSym3 mass;                          // (Ia^-1 + Ib^-1)^-1, world
    WideSym3 inv_inertia_a, inv_inertia_b;  // world, fixed for the step
    Wide3 impulse;                          // accumulated; B gets it, A its opposite
};

// An awake joint as listed for the step: what its colour and packing depend on.
struct JointRef {
    std::uint32_t joint = 0;     // slot in world.joints
    std::uint32_t a = 0, b = 0;  // solver bodies
    std::uint32_t type = 0;      // JointType: ball-socket joints are packed kLanes at a time
};

// A touching manifold of an awake contact, as listed and coloured for the step.
struct ManifoldRef {
    std::uint32_t contact = 0;
    std::uint32_t manifold = 0;
    std::uint32_t a = 0, b = 0;  // solver bodies
};

// kLanes manifolds of one colour solved together, one per lane (structure of arrays).
// They share no dynamic body, so the lanes never write the same body. Lanes past the
// colour's end hold no manifold: both bodies are the immovable one and nothing is written.
struct WideContact {
    // Laid out by the passes that read it: first what all three read (the warm start, the
    // biased and the relax pass), then what only the two solve passes read, then what only
    // the biased pass reads, then what only preparing, storing and restitution read. The
    // warm start streams the first part alone, the relax pass the first two, and every pass
    // but restitution leaves the last alone.
    std::uint32_t a[kLanes] = {}, b[kLanes] = {};       // solver bodies per lane
    int lanes = 0;                                      // lanes holding a manifold
    std::uint8_t slot_points[kMaxManifoldPoints] = {};  // lanes with a point in each slot: the work counters
    // A lane's body has a translation lock: its passes take each body's inverse mass per
    // world axis (contact_solver.cpp), the others the scalar below.
    bool locked = false;
    // A lane bounces (restitution) or reports hits (kContactReports): the passes keep
    // the points' largest pushes and approach speeds (below). Else nothing reads them.
    bool tracks_push = false;
    // A lane's contact has rolling resistance: its rows are in `rolling` (set with it by
    // prepare_wide), which no pass reads otherwise.
    bool rolls = false;
    // The lanes (bit l for lane l) whose manifold lands: two points or more about to touch,
    // the bodies closing faster than the settled speed as the step begins. Every pass
    // sweeps their normal rows until they settle (solve_wide).
    std::uint8_t sweep_lanes = 0;
    WideRolling* rolling = nullptr;  // this wide contact's in SolverScratch::rolling, where it rolls
    // Push-out of deep overlap (split impulse), per lane: the impulse of one row through
    // the overlap's centre on the push-out velocities, kept over the step's substeps. The
    // rows' anchors live apart (SolverScratch::push_anchors): they are rarely used, and
    // every pass streams the wide contacts.
    float push_impulse[kLanes] = {};
    Wide3 normal;
    Wide inv_mass_a{}, inv_mass_b{};
    Wide friction{};
    // Central friction (Box3D's): two tangent rows at the manifold's friction centre,
    // coupled by their 2x2 effective mass, and a twist row about the normal; their cones
    // scale with the manifold's total normal impulse. Three rows per manifold instead of
    // two per point, and no point's order favoured over another's.
    Wide3 tangent[2];
    WideRow friction_row[2];  // the tangents' angular terms at the centre
    Wide friction_impulse[2]{};
    Wide twist_impulse{};
    WideRow twist_row;  // Ia^-1 n, Ib^-1 n
    WidePointRow point_rows[kMaxManifoldPoints];
    // Read by the solve passes only.
    // Radius of each body's round part (sphere, capsule; else 0): its surface point along
    // the normal does not turn with the body, so a rolling ball's contact stays below it.
    Wide radius_a{}, radius_b{};
    Wide3 center_a, center_b;  // the friction centre from each centre of mass
    // How fast the friction centre's relative surface velocity along each tangent changes
    // as the bodies turn through the step: its anchors are fixed offsets from the centres
    // of mass, where the surface points under them turn (prepare_friction).
    Wide friction_turn[2]{};
    Wide friction_mass[3]{};  // inverse of the 2x2 tangent matrix: (0,0), (0,1), (1,1)
    Wide twist_mass{};
    WidePoint points[kMaxManifoldPoints];
    // Read by the biased pass only.
    Wide against_static{};  // 1 where a lane's other body is static: its contact is stiffer
    // Per point slot: overlap the soft row corrects itself; deeper overlap is pushed out.
    // The recovery depth, or deeper where the point's load (its last impulse) compresses
    // the soft contact further: a heavy body rests where its spring holds it.
    Wide recovery[kMaxManifoldPoints]{};
    std::uint32_t ref[kLanes] = {};  // manifold ref per lane: for preparing and storing
    // Read by restitution and hit events only, so last: a wide contact that tracks no
    // push leaves these lines alone in every pass.
    Wide restitution{};
    Wide gravity_normal{};                          // relative acceleration of B from A along the normal, from gravity
    Wide max_normal_impulse[kMaxManifoldPoints]{};  // per point slot: the largest push of the step
    Wide relative_velocity[kMaxManifoldPoints]{};   // per point slot: approach speed at impact
};

using Vec2 = Eigen::Matrix<Real, 2, 1>;
using Mat2 = Eigen::Matrix<Real, 2, 2>;

// One joint as the solver sees it for a step (joint_solver.cpp): frames turned into
// world at the step's start (the substeps rotate them by each body's dq), and the
// accumulated impulses (warm started from Joint).
struct JointConstraint {
    std::uint32_t a = 0, b = 0;  // solver bodies, as for contacts
    std::uint32_t joint = 0;     // slot in world.joints
    JointType type = JointType::BallSocket;
    Vec3 ra = Vec3::Zero();  // anchors from each centre of mass, world
    Vec3 rb = Vec3::Zero();
    Vec3 delta_center = Vec3::Zero();  // B's centre of mass minus A's

    // Hinge: A's axis, two perpendiculars of B's axis (the alignment rows), angle references.
    // Swing-twist: each body's twist axis (axis_a, axis_b) and twist references.
    // Prismatic: the slide axis (axis_a) and two perpendiculars of it (perp_a), on A.
    Vec3 axis_a = Vec3::UnitZ();
    Vec3 axis_b = Vec3::UnitZ();
    Vec3 perp_b[2] = {Vec3::UnitX(), Vec3::UnitY()};
    Vec3 ref_a = Vec3::UnitX(), ref_b = Vec3::UnitX();
    Vec3 perp_a[2] = {Vec3::UnitY(), Vec3::UnitZ()};
    Vec3 target = Vec3::Zero();  // motor: B's anchor's target from A's anchor, world
    // Fixed: the rotation that takes B's target orientation to its actual one, world.
    Quat rotation_error = Quat::Identity();
    Mat3 rotation_mass = Mat3::Zero();  // fixed, swing-twist friction
    // Effective masses of the other rows are computed as they are solved, from the
    // frames then: a light body can turn far within one step.
    Vec3 axis = Vec3::UnitX();  // distance: direction at the step's start (if the anchors meet)
    Softness spring;            // distance, prismatic spring
    Softness limit_spring;      // hinge: a soft limit's spring (soft_limit)
    Softness angular_spring;    // motor, with enable_angular_spring (linear: spring, enable_spring)
    bool enable_angular_spring = false;
    Real max_torque_impulse = 0;  // motor (max_motor_impulse: its force)

    // Parameters, copied so the hot loop reads one struct.
    bool enable_limit = false, enable_motor = false, enable_spring = false, soft_limit = false;
    Real lower = 0, upper = 0;  // hinge angles, distance lengths or twist range
    Real cone = 0;              // swing-twist: the cone's half angle
    Real max_friction_impulse = 0;
    Real rest_length = 0;         // distance; prismatic: the anchors' offset along the axis at creation
    Real target_translation = 0;  // prismatic spring's
    Real motor_speed = 0, max_motor_impulse = 0;
    Real spring_hertz = 0;

    // Accumulated impulses.
    Vec3 linear_impulse = Vec3::Zero();
    Vec3 angular_impulse = Vec3::Zero();  // fixed; swing-twist friction
    Vec2 align_impulse = Vec2::Zero();    // hinge, along the two alignment rows; prismatic, perp_a
    Real axial_impulse = 0, motor_impulse = 0, lower_impulse = 0, upper_impulse = 0;
    Real swing_impulse = 0;
};

// kLanes joints of one colour and one type solved together, one per lane (joint_lanes.cpp),
// as a WideContact solves manifolds: a chain or a net of ball-sockets, or ragdolls of
// swing-twist joints and hinges, is most of its step. Every lane joint has the point row
// (a ball-socket's only row, the point part of the others), kept here; a swing-twist or
// hinge block's angular rows are kept apart (`angular` indexes SolverScratch's
// wide_swing_twists or wide_hinges), so a ball-socket pass streams only what it reads.
// Lanes past `lanes` hold no joint: both bodies are the immovable one. Made from the
// joints' JointConstraints each step, and their impulses handed back.
struct WideJoint {
    std::uint32_t a[kLanes] = {}, b[kLanes] = {};  // solver bodies per lane
    std::uint32_t joint[kLanes] = {};              // index in SolverScratch::joints
    int lanes = 0;
    JointType type = JointType::BallSocket;
    std::uint32_t angular = 0;
    Wide3 ra, rb;        // anchors from each centre of mass at the step's start, world
    Wide3 delta_center;  // B's centre of mass minus A's at the step's start
    Wide inv_mass_a{}, inv_mass_b{};
    WideSym3 inv_inertia_a, inv_inertia_b;  // world, at the step's start (WideMotion's turn them)
    Wide3 impulse;                          // accumulated (JointConstraint::linear_impulse)
    bool turns_a = false, turns_b = false;  // a lane's A or B has an inertia that turning changes
};

// A swing-twist block's angular rows (joint_swing_twist.cpp): JointConstraint's, per lane.
struct WideSwingTwist {
    Wide3 axis_a, axis_b, ref_a, ref_b;  // twist axes and references, world at the step's start
    Wide cone{}, lower{}, upper{};
    WideMask limits_cone{}, limits_twist{};  // lanes whose cone or twist range limits anything
    Wide max_friction_impulse{};             // 0 where there is no friction
    WideSym3 rotation_mass;                  // (Ia^-1 + Ib^-1)^-1, the friction's
    Wide3 friction_impulse;                  // JointConstraint::angular_impulse
    Wide swing_impulse{}, lower_impulse{}, upper_impulse{};
};

// A hinge block's angular rows (joint_hinge.cpp): JointConstraint's, per lane.
struct WideHinge {
    Wide3 axis_a, perp_b[2], ref_a, ref_b;  // world at the step's start
    Wide lower{}, upper{};
    WideMask limited{}, soft_limit{};
    Wide spring_bias_rate{}, spring_mass_scale{}, spring_impulse_scale{};  // a soft limit's
    Wide motor_speed{}, max_motor_impulse{};                               // 0 without a motor
    Wide align_impulse[2]{};
    Wide motor_impulse{}, lower_impulse{}, upper_impulse{};
};

// How joints are solved in one pass: soft position correction with use_bias, none
// (relax) without.
struct JointSolveParams {
    Softness soft;
    Real inv_h = 0;
    bool use_bias = true;
};

inline constexpr int kColorCount = 24;

// What one phase of the step's solver loop does (solver.cpp): a pass over the bodies,
// or over one colour's constraints (color == kColorCount: the overflow, one block).
enum class Pass : std::uint8_t {
    PrepareContacts,
    PrepareJoints,
    IntegrateVelocities,
    WarmStart,
    Solve,
    IntegratePositions,
    IntegrateKinematic,
    Relax,
    Restitution,
    StoreImpulses,
    StoreJointLanes,
    StoreJoints,
    FinalizeBodies
};
// A phase that carries a body pass (SolverScratch::fold_body_passes): a warm-start phase (or
// the first solve phase of a substep the relax pass warm started, warm_in_relax) or first
// relax phase of a folded step integrates, before a constraint, the bodies it is the first
// of its pass to touch (first_touch), and in its items past `constraints`, chunks of the
// bodies no constraint touches; a StoreImpulses phase finalizes every awake body in chunks
// past them.
//
// A pass's first colour may carry the tail of the pass before it (SolverScratch::tail_plan):
// its item 0 runs the tail's phases, then its own constraints that touch a body of the tail
// (lead_blocked); its other items are its other constraints (lead_free), then the chunks.
// StoreAndFinalize may carry the last pass's tail (`color` its first colour): item 0 runs it,
// stores its contacts' impulses and finalizes its bodies; then the other contacts, then
// chunks of the other bodies.
struct SolverPhase {
    Pass pass = Pass::Solve;
    int color = 0;
    bool integrates = false;        // carries its body pass
    std::uint32_t constraints = 0;  // items of its own pass, when it does; the chunks of bodies follow
    std::uint32_t tail_begin = 0;   // the tail it carries: tail_plan[tail_begin, tail_end)
    std::uint32_t tail_end = 0;
    bool warms = false;         // a relax phase that warm starts the next substep too (warm_in_relax)
    std::uint32_t substep = 0;  // of a constraint pass: which substep of the step it is in
};

// Support mass scaling (support_scales.cpp): the factors a manifold's rows multiply each
// body's inverse mass and inertia by; 1 but for a light body carrying a heavier one.
struct SupportScale {
    Real a = 1, b = 1;
    Real lower() const { return std::min(a, b); }  // the lower body's (the other's is 1)
};
// A support contact: manifold ref k's upper body rests on its lower one.
struct SupportEdge {
    std::uint32_t ref = 0;
    std::uint32_t lower = 0, upper = 0;  // solver bodies
};

// The arrays on RawRoomAllocator are written whole before they are read in every step
// that grows them (their comments say where): a resize does not zero them.
struct SolverScratch {
    RawRoomVector<SolverBody> bodies;  // awake bodies, then the static body (prepare_body_chunk)
    // Per solver body, apart from it (SolverBody says why): its push-out velocities, and
    // BodyDesc::gravity_scale of a dynamic body (else 0) so that integrate_velocities and
    // prepare_wide stay off the cold descriptions, each a cache miss (prepare_body_chunk).
    RawRoomVector<PushVelocity> push_velocities;
    RawRoomVector<Real> gravity_scales;
    // Per solver body: the next substep's warm start of its constraints, added up by the relax
    // pass that ends a substep (warm_in_relax) and added to the body's velocities as the next
    // substep integrates them (zero for a body no contact touches, and after that).
    RawRoomVector<PushVelocity> warm_velocities;
    // Touching manifolds of awake contacts, in contact order (list_range's ranges, joined).
    RawRoomVector<ManifoldRef> manifolds;
    // The lists of fixed ranges of contacts (list_range), before they are joined.
    struct ListedRange {
        std::vector<ManifoldRef> refs;
        std::uint32_t materials = 0;  // their contacts' summary bits but the point counts (restitution, rolls)
        std::size_t first = 0;        // where its refs go in manifolds
        bool same = false;            // they were in colored_manifolds where they go (join_range)
    };
    std::vector<ListedRange> listed;
    // What the listed manifolds' contacts have between them: the or of their summary bits
    // but the point counts (kSummaryRestitution, kSummaryRolls; world.hpp).
    std::uint32_t listed_materials = 0;
    // The colouring below is a function of the manifold list, the joints and the bodies
    // (which are dynamic) alone: what it was made for, to reuse it while nothing changed.
    RawRoomVector<ManifoldRef> colored_manifolds;  // manifolds, as join_range leaves it
    bool same_manifolds = false;                   // this step's manifolds are the last colouring's
    std::size_t colored_bodies = 0;
    std::uint64_t colored_body_set = ~std::uint64_t{0};  // World::body_set_version then
    std::vector<JointRef> colored_joints;                // the joint list then
    bool reuse_colors = true;                            // false colours every step (tests compare the two)
    std::vector<std::uint32_t> colors[kColorCount];      // manifold refs per colour
    std::vector<std::uint32_t> overflow;                 // refs that fit no colour, solved serially
    bool sort_colors = true;  // each colour's refs by their lower dynamic body (solver.cpp); false: as coloured
    // sort_colors' working lists, kept for their capacity: each manifold ref's colour (-1: the overflow), per
    // solver body where its manifolds start in the sorted list, and the coloured refs sorted.
    std::vector<std::int8_t> manifold_colors;
    std::vector<std::uint32_t> body_starts;
    std::vector<std::uint32_t> sorted_refs;
    // The colours' manifolds kLanes at a time, then the overflow one by one (pack_contacts
    // writes their lanes, prepare_wide every other field).
    RawRoomVector<WideContact> wide;
    RawRoomVector<PushAnchors> push_anchors;  // kLanes per wide contact: its push-out rows' (push_out, before read)
    // One per wide contact where any listed manifold rolls (kSummaryRolls in
    // listed_materials), else none: written by prepare_wide where a lane rolls, else unread.
    RawRoomVector<WideRolling> rolling;
    std::uint32_t wide_begin[kColorCount + 1] = {};  // colour c holds wide[wide_begin[c], wide_begin[c + 1])
    std::vector<JointConstraint> joints;             // awake joints, in slot order
    std::vector<JointRef> joint_refs;                // the same, as listed
    // Joint indices per colour (joints are coloured first), but for the ball-socket,
    // swing-twist and hinge joints of bodies without motion locks: those are packed kLanes
    // at a time, colour c's in wide_joints[wide_joint_begin[c], wide_joint_begin[c + 1]).
    std::vector<std::uint32_t> joint_colors[kColorCount];
    std::vector<WideJoint> wide_joints;
    std::vector<WideSwingTwist> wide_swing_twists;  // the angular rows of wide_joints' swing-twist blocks
    std::vector<WideHinge> wide_hinges;             // and of their hinge blocks
    std::uint32_t wide_joint_begin[kColorCount + 1] = {};
    std::vector<std::uint32_t> joint_overflow;
    HugePageVector<std::uint32_t> body_colors;  // per solver body: a bit for each colour it is in
    // Per manifold ref, or empty when every scale is 1 (most steps of most scenes).
    std::vector<SupportScale> support_scales;
    // Whether every awake dynamic body has the same inverse mass (from the least and
    // greatest of each chunk of bodies, prepare_bodies_and_list_manifolds): then no scale
    // differs from 1.
    bool one_dynamic_mass = false;
    // Per chunk of bodies (prepare_body_chunk): the least and greatest inverse mass of its
    // dynamic bodies.
    struct BodyChunk {
        Real least_inv_mass = kHuge;
        Real greatest_inv_mass = -kHuge;
    };
    std::vector<BodyChunk> body_chunks;
    // The body passes folded into the constraint passes (solver.cpp), so a step has fewer
    // phases and barriers: each body's velocities are integrated just before the first
    // constraint of a warm-start pass (or of the first solve pass, where the relax pass warm
    // started the substep: warm_in_relax) that touches it, its positions just before the first
    // of the first relax pass (two phases fewer a substep), and the bodies are finalized in
    // the phase that stores the contacts' impulses. Each body's arithmetic and its order
    // against its own constraints stay the same: bitwise the results of the passes of
    // their own. Only the dynamic bodies' integration folds: a kinematic body is read by
    // many constraints of a colour at once, so its positions move in a phase of their own
    // before the first relax pass (its velocities are constant over a step). The
    // finalizing folds only without joints (their impulses are stored in phases of their own).
    bool fold_body_passes = true;  // false: always the passes of their own (tests compare the two)
    bool folded = false;           // this step's plan folds the integration
    // The warm start of every substep but the first made by the relax pass before it, each
    // constraint's right after it is relaxed, so a substep has one pass over the colours fewer:
    // nothing changes a constraint's impulses, masses or bodies' poses (a joint's anchors turn
    // with them) between its relax and the next warm start (the positions move before the
    // relax pass), and the velocity changes, added up apart from the velocities the relax pass
    // still reads (warm_velocities), reach them after the next substep integrates its
    // velocities, as the warm start's would. The same motion up to rounding (the changes are
    // summed before they are added); only on a folded step, with a solve and a relax pass.
    bool warm_in_relax = true;  // false: every substep its warm start pass (tests compare the two)
    bool warms = false;         // this step's plan warm starts in its relax passes
    // The bodies that no constraint before them in a pass touches, constraint by constraint
    // in a pass's order: item k of colour c (its wide joints, other joints, wide contacts)
    // has first_touched[first_touch[i], first_touch[i + 1]) with i = first_item[c] + k, so a
    // block's are one span; the overflow is one item. And the awake bodies that no
    // constraint touches. Made with the colouring (find_first_touches).
    std::vector<std::uint32_t> first_touch;  // an offset per item, and one past the last
    std::uint32_t first_item[kColorCount + 1] = {};
    std::vector<std::uint32_t> first_touched;
    std::vector<std::uint32_t> untouched;
    std::vector<std::uint32_t> kinematic;  // the awake kinematic bodies, in awake order
    // find_first_touches' scratch, kept for its capacity: per body whether the overflow
    // touched it (only with an overflow), the overflow's first touches, and per chunk of
    // bodies its untouched and kinematic counts.
    std::vector<std::uint8_t> touched;
    std::vector<std::uint32_t> overflow_touches;
    std::vector<std::uint32_t> touch_counts;
    std::vector<SupportEdge> support_edges;  // find_support_scales' working lists, kept for their capacity
    std::vector<std::uint32_t> support_first, support_by_lower, support_queue;
    std::vector<std::uint8_t> supported;
    std::vector<Phase> phases;      // the step's solver loop, run by run_phases
    std::vector<SolverPhase> plan;  // what each phase does
    // A pass's last colours of a few wide contacts each (its tail) are a round of run_phases:
    // one worker runs them while the others wait, then a barrier. Without joints or an
    // overflow, the tail runs instead in the first item of the next pass's first colour,
    // before those of that colour's wide contacts that share a dynamic body with it
    // (lead_blocked, few: the tail's bodies are few); its other wide contacts (lead_free) run
    // beside the tail. Each body meets its constraints in the same order: the same results,
    // a barrier fewer a pass. The tail phases (tail_plan), and the first colour's wide
    // contacts, as indices into it, made once per colouring (lead_made).
    struct TailPhase {
        SolverPhase phase;
        std::uint32_t items = 0;  // its Phase's count
    };
    std::vector<TailPhase> tail_plan;
    std::vector<std::uint32_t> lead_blocked, lead_free;
    std::vector<std::uint8_t> in_tail;       // per solver body: whether a tail colour writes it
    std::vector<std::uint32_t> tail_bodies;  // those bodies, in order
    bool lead_made = false;
    bool carry_tails = true;  // false: every tail a round of its own (tests compare the two)
};

// How contacts are solved in one pass (contact_solver.cpp): soft push-out with use_bias,
// none (relax) without.
struct ContactSolveParams {
    Softness soft;
    Softness static_soft;  // against a static body (Box3D's): twice the hertz, half the damping ratio
    Real inv_h = 0;
    Real push_out = 0;        // push-out speed
    Real slop = 0;            // gaps wider than this carry no friction
    Real recovery_depth = 0;  // overlap beyond this is pushed out by the split impulse
    Real settled_speed = 0;   // a lane's normal rows are swept again while one changes a point's speed more
    Real step = 0;            // the step's length, dt
    // When in the step a pass's friction matches the surfaces' velocities (solve_friction):
    // the middle of its substep for the biased pass, whose velocities move the bodies
    // through it, and the substep's end for the relax pass, whose velocities start the next.
    Real turn_time = 0;
    // How long gravity has acted on the velocities a pass solves: to its substep's end.
    Real fall_time = 0;
    // How deep a point's last impulse holds its soft row at rest, per unit impulse over
    // the effective mass (impulse_scale x impulse = mass x mass_scale x bias_rate x depth),
    // for soft and static_soft; set with them (held_per_impulse()).
    Real held_per_impulse = 0, static_held_per_impulse = 0;
    bool use_bias = true;
};

inline Real held_per_impulse(const Softness& soft) { return soft.impulse_scale / (soft.mass_scale * soft.bias_rate); }

// support_scales.cpp: fills scratch.support_scales from the step's manifolds and bodies.
void find_support_scales(const World& world, SolverScratch& scratch);

// Manifold ref k's support scales this step (1 and 1 where the list is empty).
inline SupportScale support_scale(const SolverScratch& scratch, std::uint32_t k) {
    return scratch.support_scales.empty() ? SupportScale{} : scratch.support_scales[k];
}

// contact_solver.cpp. pack_contacts lays the colours' manifolds out in scratch.wide
// (which manifold and bodies each lane holds); prepare_contacts fills in the rest from
// the manifolds and bodies of the step; the others run per wide contact from the
// colour loops.
void pack_contacts(JobSystem& jobs, SolverScratch& scratch);
// The rolling rows for this step's wide contacts where any listed manifold rolls, else
// none (their memory given back): after pack_contacts, every step (a body's rolling
// resistance may change while the colouring is kept).
void size_rolling_rows(SolverScratch& scratch);
void prepare_contacts(const World& world, SolverScratch& scratch, const ContactSolveParams& params, std::uint32_t lo,
                      std::uint32_t hi);  // wide [lo, hi)
// push_anchors: the wide contact's kLanes push-out anchors (SolverScratch::push_anchors).
// push: the solver bodies' push-out velocities (SolverScratch::push_velocities).
void warm_start_contact(WideContact& wc, const PushAnchors* push_anchors, SolverBody* bodies, PushVelocity* push);
// The points whose rows ran are counted into `counts` (the worker's).
void solve_contact(WideContact& wc, PushAnchors* push_anchors, SolverBody* bodies, PushVelocity* push,
                   const ContactSolveParams& params, EffectCounts& counts);
// The relax pass's solve_contact (params without bias), then the next substep's warm start:
// its velocity changes added to `warm` (SolverScratch::warm_velocities), its push-out ones
// to `push`, as warm_start_contact would apply them.
void relax_and_warm_start_contact(WideContact& wc, PushAnchors* push_anchors, SolverBody* bodies, PushVelocity* push,
                                  PushVelocity* warm, const ContactSolveParams& params, EffectCounts& counts);
void apply_restitution(WideContact& wc, SolverBody* bodies, Real threshold, Real max_speed, Real h,
                       EffectCounts& counts);
void store_contact_impulses(World& world, const SolverScratch& scratch, std::uint32_t lo, std::uint32_t hi);

// joint_solver.cpp. prepare_joints lists the awake joints (nothing when there are
// none) and prepares them from the bodies of scratch; the others run per joint from
// the colour loops, so a joint only touches its own two solver bodies.
Softness joint_softness(const SolverSettings& settings, Real h);  // joint_hertz, capped; 0: the cap
void prepare_joints(World& world, SolverScratch& scratch, Real h);
void warm_start_joint(JointConstraint& jc, SolverBody* bodies);
void solve_joint(JointConstraint& jc, SolverBody* bodies, const JointSolveParams& params, EffectCounts& counts);
// solve_joint in the relax pass, then the next substep's warm start added to `warm`
// (relax_and_warm_start_contact says how).
void relax_and_warm_start_joint(JointConstraint& jc, SolverBody* bodies, const JointSolveParams& params,
                                EffectCounts& counts, PushVelocity* warm);
void store_joint_impulses(World& world, const SolverScratch& scratch, std::uint32_t lo,
                          std::uint32_t hi);  // joints [lo, hi)

// joint_lanes.cpp. pack_joint_lanes takes the ball-socket, swing-twist and hinge joints
// out of the colours' joint lists (after colouring) and lays them out kLanes at a time,
// one type to a block; prepare_joint_lanes fills wide_joints [lo, hi) from their prepared
// JointConstraints; store_joint_lane_impulses hands the impulses of wide_joints [lo, hi)
// back to them (before store_joint_impulses).
void pack_joint_lanes(SolverScratch& scratch);
void prepare_joint_lanes(SolverScratch& scratch, std::uint32_t lo, std::uint32_t hi);
void warm_start_joint_lanes(const SolverScratch& scratch, const WideJoint& wj, SolverBody* bodies);
void solve_joint_lanes(SolverScratch& scratch, WideJoint& wj, SolverBody* bodies, const JointSolveParams& params,
                       EffectCounts& counts);
void relax_and_warm_start_joint_lanes(SolverScratch& scratch, WideJoint& wj, SolverBody* bodies,
                                      const JointSolveParams& params, EffectCounts& counts, PushVelocity* warm);
void store_joint_lane_impulses(SolverScratch& scratch, std::uint32_t lo, std::uint32_t hi);

}  // namespace spindle
