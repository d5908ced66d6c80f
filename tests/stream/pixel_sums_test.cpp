// The occlusion stage adds each unblocked shadow ray's light into its hit's local colour, and
// the hits' local colours go into their pixels with the pixel's sum held in registers along a
// run of its rays (stream/shade_stage.h, add_unblocked_to_hits and add_runs). The pictures
// rely on this giving the bits of one float addition per term, in a fixed order: the same
// picture for every -j, slice size and instruction set.
#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include "stream/shade_stage.h"

using namespace streamrt;

namespace {

// Values whose sums round differently when regrouped: 1 + 2^-24 + 2^-24 is 1 in order, but
// 1 + 2^-23 when the two small terms are added first.
constexpr float kTiny = 0x1p-24f;

}  // namespace

TEST_CASE("pixel sums: runs of a pixel's rays add in stream order, and a pixel met again continues its sum") {
    // Rays in run order: pixels 2, 2, 0, 2, 0, 0 through an order that reads the slice backwards.
    const std::vector<std::int32_t> pixel_of_ray{0, 0, 2, 0, 2, 2};  // slice index -> pixel
    const std::vector<std::int32_t> order{5, 4, 3, 2, 1, 0};         // run order -> slice index
    const std::vector<float> r{kTiny, kTiny, 1.f, kTiny, kTiny, 0.5f};
    const std::vector<float> g{1.f, 2.f, 3.f, 4.f, 5.f, 6.f};
    const std::vector<float> b{0.f, 0.f, 0.f, 0.f, 0.f, 0.25f};
    std::vector<float> accum(9, 0.f);
    accum[6] = 1.f;  // pixel 2's red starts at 1
    stage_detail::add_runs(accum.data(), pixel_of_ray.data(), order.data(), r.data(), g.data(), b.data(), r.size());
    // Pixel 2 takes rays 0, 1 and 3 of the run order: ((1 + tiny) + tiny) + tiny, each rounding to 1.
    CHECK(accum[6] == 1.f);
    CHECK(accum[7] == 1.f + 2.f + 4.f);
    CHECK(accum[8] == 0.f);
    // Pixel 0 takes rays 2, 4 and 5: 1 + tiny + 0.5.
    CHECK(accum[0] == 1.5f);
    CHECK(accum[1] == 3.f + 5.f + 6.f);
    CHECK(accum[2] == 0.25f);
    // The reference: one addition per ray, in the same order.
    std::vector<float> one_by_one(9, 0.f);
    one_by_one[6] = 1.f;
    for (std::size_t j = 0; j < r.size(); ++j)
        stage_detail::add(one_by_one.data(), pixel_of_ray[std::size_t(order[j])], {r[j], g[j], b[j]});
    CHECK(accum == one_by_one);
}

TEST_CASE("pixel sums: only unblocked shadow rays (t_max > 0) add their colour to their hit, in stream order") {
    ShadowStream s;
    s.reserve(6);
    const std::int32_t hit[] = {1, 1, 0, 1, 0, 1};  // the hit's place (SortedHits::order), not a pixel
    const float t_max[] = {2.f, 0.f, 1.f, 3.f, 0.f, 1.f};  // rays 1 and 4 are blocked
    const float red[] = {1.f, 100.f, 0.25f, kTiny, 100.f, kTiny};
    for (int i = 0; i < 6; ++i) {
        s.pixel[std::size_t(i)] = hit[i];
        s.t_max[std::size_t(i)] = t_max[i];
        s.cr[std::size_t(i)] = red[i];
        s.cg[std::size_t(i)] = float(i);
        s.cb[std::size_t(i)] = 1.f;
    }
    s.count = 6;
    // The hits' local colours before their light: hit 1's red starts at 0, so its terms sum
    // to 1 + tiny + tiny = 1 in stream order.
    std::vector<float> lr{0.5f, 0.f}, lg{10.f, 20.f}, lb{0.f, 0.f};
    stage_detail::add_unblocked_to_hits(lr.data(), lg.data(), lb.data(), s);
    CHECK(lr[0] == 0.75f);             // 0.5 + ray 2 (ray 4 is blocked)
    CHECK(lg[0] == 10.f + 2.f);        // cg of ray 2
    CHECK(lb[0] == 1.f);
    CHECK(lr[1] == 1.f);               // rays 0, 3, 5: (1 + tiny) + tiny rounds to 1
    CHECK(lg[1] == 20.f + 0.f + 3.f + 5.f);
    CHECK(lb[1] == 3.f);
}
