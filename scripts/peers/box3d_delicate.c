// Box3D beside Spindle's tests/stability/delicate_test.cpp: the same card house and arches,
// built the same way, sleep off, at Box3D's defaults (4 substeps at 1/60 s, 30 Hz contacts)
// or at the substeps and contact hertz given. The numbers in docs/accuracy.md ("Delicate
// structures") came from it. Not part of the build (Box3D is no Debian package):
//   git clone https://github.com/erincatto/box3d && cd box3d && git checkout 30c67b5
//   cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DBOX3D_SAMPLES=OFF -DBOX3D_UNIT_TESTS=OFF
//   cmake --build build --target box3d
//   cc -O2 -Iinclude box3d_delicate.c build/src/libbox3d.a -lm -lpthread -o delicate
//   ./delicate [substeps [contact_hertz]]   (Box3D caps the hertz at an eighth of the substep rate)
#include <box3d/box3d.h>
#include <box3d/collision.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static const double kPi = 3.14159265358979323846;
static const double kGap = 1e-4;
static int g_substeps = 4;
static float g_hertz = -1;

static b3WorldId make_world(void) {
    b3WorldDef def = b3DefaultWorldDef();
    def.gravity = (b3Vec3){0, -9.81f, 0};
    def.enableSleep = false;
    if (g_hertz > 0) def.contactHertz = g_hertz;
    return b3CreateWorld(&def);
}

static void static_box(b3WorldId world, double hx, double hy, double hz, double y, float friction) {
    b3BodyDef bd = b3DefaultBodyDef();
    bd.position = (b3Pos){0, (float)y, 0};
    b3BodyId body = b3CreateBody(world, &bd);
    b3BoxHull box = b3MakeBoxHull((float)hx, (float)hy, (float)hz);
    b3ShapeDef sd = b3DefaultShapeDef();
    sd.baseMaterial.friction = friction;
    b3CreateHullShape(body, &sd, &box.base);
}

static b3Quat about_z(double angle) {
    return (b3Quat){{0, 0, (float)sin(0.5 * angle)}, (float)cos(0.5 * angle)};
}

// Card: 88 x 63 x 2 mm, 700 kg/m^3, friction 0.5.
static const double ca = 0.044, cb = 0.001, cc = 0.0315;
static b3BodyId add_card(b3WorldId world, double x, double y, double angle) {
    b3BodyDef bd = b3DefaultBodyDef();
    bd.type = b3_dynamicBody;
    bd.position = (b3Pos){(float)x, (float)y, 0};
    bd.rotation = about_z(angle);
    b3BodyId body = b3CreateBody(world, &bd);
    b3BoxHull box = b3MakeBoxHull((float)ca, (float)cb, (float)cc);
    b3ShapeDef sd = b3DefaultShapeDef();
    sd.density = 700;
    sd.baseMaterial.friction = 0.5f;
    b3CreateHullShape(body, &sd, &box.base);
    return body;
}

static double top_of_card(b3BodyId body) {
    b3Pos p = b3Body_GetPosition(body);
    b3Quat q = b3Body_GetRotation(body);
    // rotation matrix row 1 (y) of a quaternion
    double x = q.v.x, y = q.v.y, z = q.v.z, w = q.s;
    double r10 = 2 * (x * y + w * z), r11 = 1 - 2 * (x * x + z * z), r12 = 2 * (y * z - w * x);
    return p.y + fabs(r10) * ca + fabs(r11) * cb + fabs(r12) * cc;
}

static double angle_z(b3BodyId body) {
    b3Quat q = b3Body_GetRotation(body);
    return 2 * atan2(q.v.z, q.s);
}

static void card_house(int levels) {
    b3WorldId world = make_world();
    static_box(world, 1, 0.5, 1, -0.5, 0.5f);
    const double lean = 68 * kPi / 180, c = cos(lean), s = sin(lean);
    const double spacing = 2 * ca + kGap, pair_height = 2 * ca * s + 2 * cb * c;
    b3BodyId cards[64];
    int n = 0;
    b3BodyId top[2];
    double floor_y = 0;
    for (int level = 0; level < levels; ++level) {
        int pairs = levels - level;
        double centre_y = floor_y + kGap + ca * s + cb * c;
        for (int j = 0; j < pairs; ++j) {
            double apex = (j - 0.5 * (pairs - 1)) * spacing, half = ca * c + cb * s;
            top[0] = cards[n++] = add_card(world, apex - half, centre_y, lean);
            top[1] = cards[n++] = add_card(world, apex + half, centre_y, -lean);
        }
        double flat_y = floor_y + kGap + pair_height + kGap + cb;
        for (int j = 0; j + 1 < pairs; ++j) {
            double apex = (j - 0.5 * (pairs - 1)) * spacing;
            cards[n++] = add_card(world, apex + 0.5 * spacing, flat_y, 0);
        }
        floor_y = flat_y + cb;
    }
    double built = fmax(top_of_card(top[0]), top_of_card(top[1]));
    double a0 = angle_z(top[0]), a1 = angle_z(top[1]);
    double worst = 0, rack = 0, drop1 = 0;
    for (int step = 0; step < 600; ++step) {
        b3World_Step(world, 1.0f / 60, g_substeps);
        double top_y = fmax(top_of_card(top[0]), top_of_card(top[1]));
        worst = fmax(worst, built - top_y);
        double r = fmax(fabs(angle_z(top[0]) - a0), fabs(angle_z(top[1]) - a1)) * 180 / kPi;
        rack = fmax(rack, r);
        if (step == 59) drop1 = built - top_y;
    }
    double end = built - fmax(top_of_card(top[0]), top_of_card(top[1]));
    double speed = 0;
    for (int i = 0; i < n; ++i) {
        b3Vec3 v = b3Body_GetLinearVelocity(cards[i]);
        speed = fmax(speed, sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
    }
    printf("box3d card house %d levels (%d cards), %d substeps: top drop %.2f mm at 1 s, %.2f mm worst, %.2f mm end; "
           "top pair racked %.2f deg at worst; fastest at end %.2g m/s\n",
           levels, n, g_substeps, 1000 * drop1, 1000 * worst, 1000 * end, rack, speed);
    b3DestroyWorld(world);
}

static void arch(int stones, double inner, double outer) {
    b3WorldId world = make_world();
    static_box(world, 5, 0.5, 2, -0.5, 0.6f);
    b3BodyId body[64];
    for (int i = 0; i < stones; ++i) {
        double from = i * kPi / stones, to = (i + 1) * kPi / stones, mid = 0.5 * (from + to);
        double r_mid = 0.5 * (inner + outer);
        double ox = r_mid * cos(mid), oy = r_mid * sin(mid);
        b3Vec3 pts[8];
        int k = 0;
        double radii[2] = {inner, outer}, angles[2] = {from, to}, zs[2] = {-0.5, 0.5};
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b)
                for (int c = 0; c < 2; ++c)
                    pts[k++] = (b3Vec3){(float)(radii[a] * cos(angles[b]) - ox), (float)(radii[a] * sin(angles[b]) - oy),
                                        (float)zs[c]};
        b3HullData* hull = b3CreateHull(pts, 8, 64);
        b3BodyDef bd = b3DefaultBodyDef();
        bd.type = b3_dynamicBody;
        bd.position = (b3Pos){(float)ox, (float)(oy + kGap), 0};
        body[i] = b3CreateBody(world, &bd);
        b3ShapeDef sd = b3DefaultShapeDef();
        sd.density = 2500;
        sd.baseMaterial.friction = 0.6f;
        b3CreateHullShape(body[i], &sd, hull);
        b3DestroyHull(hull);
    }
    b3BodyId key = body[stones / 2];
    double built = b3Body_GetPosition(key).y, worst = 0, at1 = 0;
    for (int step = 0; step < 600; ++step) {
        b3World_Step(world, 1.0f / 60, g_substeps);
        double sag = built - b3Body_GetPosition(key).y;
        worst = fmax(worst, sag);
        if (step == 59) at1 = sag;
    }
    double speed = 0;
    for (int i = 0; i < stones; ++i) {
        b3Vec3 v = b3Body_GetLinearVelocity(body[i]);
        speed = fmax(speed, sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
    }
    printf("box3d arch of %d voussoirs, radii %.2f-%.2f, %d substeps: keystone sag %.2f mm at 1 s, %.2f mm worst, "
           "%.2f mm end; fastest at end %.2g m/s\n",
           stones, inner, outer, g_substeps, 1000 * at1, 1000 * worst, 1000 * (built - b3Body_GetPosition(key).y),
           speed);
    b3DestroyWorld(world);
}

int main(int argc, char** argv) {
    if (argc > 1) g_substeps = atoi(argv[1]);
    if (argc > 2) g_hertz = (float)atof(argv[2]);
    card_house(5);
    arch(11, 2, 2.5);
    arch(21, 2, 2.3);
    return 0;
}
