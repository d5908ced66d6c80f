// Glass with the handout's fixed weights (refl, trans, no Fresnel) at total internal
// reflection: the refracted ray would leave from the reflected ray's point in its direction,
// so shade_hit (render/shading.h, both engines) sends one reflected child of weight
// refl + trans instead of two identical ones; below the critical angle, both children as
// before. Angles and directions by hand: ior 1.5, critical angle asin(1 / 1.5) = 41.81 deg.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "render/shading.h"

using namespace streamrt;

namespace {

struct Child {
    Vec3d origin, dir;
    double weight;
    RayKind kind;
};

/// Records what shade_hit sends; no lights, so no shadow rays.
struct RecordingSink {
    static constexpr bool kTestsShadowsNow = true;
    std::vector<Child> children;
    std::uint32_t light_key() const { return 0; }
    void local(const ColorT<double>&) {}
    bool occluded(const Vec3d&, const Vec3d&, double) { return false; }
    void child(bool send, const Vec3d& from, const Vec3d& dir, const ColorT<double>& weight, const ColorT<double>&,
               double, RayKind kind) {
        if (send) children.push_back({from, dir, weight.x, kind});
    }
};

/// A ray inside glass (refl 0.1, trans 0.9, ior 1.5) meeting the face z = 0, whose outward
/// normal is +z, at `degrees` from the normal.
std::vector<Child> children_at(double degrees) {
    Material glass;
    glass.ambi = 0, glass.diff = 0, glass.spec = 0, glass.refl = 0.1, glass.trans = 0.9, glass.ior = 1.5;
    const MaterialT<double> m = MaterialT<double>::from(glass);
    const ShadeRules<double> rules{5, 0.0, true, 0.0, 0.0};
    const double a = degrees * 3.14159265358979323846 / 180;
    const Vec3d d{std::sin(a), 0, std::cos(a)};
    const ArrivingRay<double> ray{Vec3d{0, 0, -1} - d, d, 1.0, 0.0, {1, 1, 1}, {1, 1, 1}};
    RecordingSink sink;
    shade_hit<true, false, true, true, false>(rules, m, static_cast<const LightT<double>*>(nullptr), 0, ray, Vec3d{0, 0, 0},
                                       Vec3d{0, 0, 1}, ColorT<double>{1, 1, 1}, true, sink);
    return sink.children;
}

}  // namespace

TEST_CASE("glass, fixed weights: total internal reflection sends one reflected ray of weight refl + trans") {
    const std::vector<Child> total = children_at(60);  // beyond 41.81 degrees
    REQUIRE(total.size() == 1);
    CHECK(total[0].kind == RayKind::Reflected);
    CHECK(total[0].weight == doctest::Approx(1.0));
    CHECK(total[0].dir.x == doctest::Approx(std::sin(60 * 3.14159265358979323846 / 180)));
    CHECK(total[0].dir.z == doctest::Approx(-0.5));  // mirrored back into the glass
    CHECK(total[0].origin.z < 0);                      // and leaving from the glass side

    const std::vector<Child> both = children_at(30);  // below: sin t = 1.5 sin 30 = 0.75
    REQUIRE(both.size() == 2);
    CHECK(both[0].kind == RayKind::Reflected);
    CHECK(both[0].weight == doctest::Approx(0.1));
    CHECK(both[0].dir.z == doctest::Approx(-std::cos(30 * 3.14159265358979323846 / 180)));
    CHECK(both[1].kind == RayKind::Refracted);
    CHECK(both[1].weight == doctest::Approx(0.9));
    CHECK(both[1].dir.x == doctest::Approx(0.75));
    CHECK(both[1].dir.z == doctest::Approx(std::sqrt(1 - 0.75 * 0.75)));
    CHECK(both[1].origin.z > 0);  // out of the glass
}
