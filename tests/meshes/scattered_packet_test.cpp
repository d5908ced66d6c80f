// The stream engine's choice between the packet and the hybrid mesh walk for one packet
// (scattered_packet_lanes, kernels/mesh_kernel.h), on 4-lane SSE2 packets whose directions'
// angles to their mean are known: the hybrid only when some live lane is more than
// acos(0.3) = 72.5 degrees from the mean.
#define STREAMRT_ISA_NAMESPACE isa_test_sse2
#include <doctest/doctest.h>

#include <cmath>

#include "kernels/mesh_kernel.h"

using namespace streamrt;
using B = xsimd::batch<float, xsimd::sse2>;

namespace {

constexpr double kPi = 3.14159265358979323846;

B four(float a, float b, float c, float d) {
    const float v[4] = {a, b, c, d};
    return B::load_unaligned(v);
}

/// Four directions at `degrees` from +z, one in each of the directions +x, -x, +y, -y, each
/// of length `length` (canonical-space directions are not unit): their mean is +z.
Vec3T<B> cone(double degrees, float length = 1.f) {
    const float s = float(std::sin(degrees * kPi / 180)) * length, c = float(std::cos(degrees * kPi / 180)) * length;
    return {four(s, -s, 0.f, 0.f), four(0.f, 0.f, s, -s), B(c)};
}

std::uint32_t lanes_for(const Vec3T<B>& d, const decltype(B(0.f) < B(0.f))& live, std::uint32_t lanes = 16) {
    return isa_test_sse2::scattered_packet_lanes(d, live, lanes);
}

}  // namespace

TEST_CASE("mesh walks: a packet takes the hybrid walk only when its rays have scattered past 72.5 degrees") {
    const auto all = B(1.f) > B(0.f);
    CHECK(lanes_for(cone(0), all) == 0);     // parallel rays
    CHECK(lanes_for(cone(70), all) == 0);    // cos 70 = 0.342 >= 0.3: the packet walk
    CHECK(lanes_for(cone(75), all) == 16);   // cos 75 = 0.259 < 0.3: single rays below 16 lanes
    CHECK(lanes_for(cone(75), all, 0) == 0);  // --mesh-hybrid 0: never
    // The length of a direction does not count (Mi scales them).
    CHECK(lanes_for(cone(70, 5.f), all) == 0);
    CHECK(lanes_for(cone(75, 0.2f), all) == 16);
    // Dead lanes do not count, in the mean either: two live rays at 70 degrees from +z on
    // either side and one along it have their mean along +z (cos 0.342 >= 0.3); a dead lane
    // along +y, were it counted, would tilt the mean to (0, 1, 1 + 2 cos 70) and put the two
    // at cos 0.294 from it.
    const float s70 = float(std::sin(70 * kPi / 180)), c70 = float(std::cos(70 * kPi / 180));
    const Vec3T<B> d{four(s70, -s70, 0.f, 0.f), four(0.f, 0.f, 0.f, 1.f), four(c70, c70, 1.f, 0.f)};
    CHECK(lanes_for(d, four(1.f, 1.f, 1.f, 0.f) > B(0.f)) == 0);
    CHECK(lanes_for(d, all) == 16);
    // No live lane or directions that cancel out: no mean to measure from, counted as scattered
    // (a packet without live lanes walks nothing either way).
    CHECK(lanes_for(cone(0), B(0.f) > B(1.f)) == 16);
    const Vec3T<B> opposite{four(1.f, -1.f, 1.f, -1.f), B(0.f), B(0.f)};
    CHECK(lanes_for(opposite, all) == 16);
}
