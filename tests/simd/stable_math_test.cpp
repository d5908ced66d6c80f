// simd/stable_math.h: the atan2 and log2 series against std:: in double over their domains,
// within the truncation bounds derived in the header plus the roundings of the evaluation;
// exact values where the reduction makes the series vanish; batches equal to scalars bit for
// bit.
#include <doctest/doctest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>

#include "simd/lanes_test_util.h"
#include "simd/stable_math.h"

using namespace streamrt;

namespace {

constexpr double kPi = 3.141592653589793;

/// The first term the atan series leaves out, at the widest reduced argument 2 - sqrt 3.
double atan_truncation() { return std::pow(2.0 - std::sqrt(3.0), 13) / 13.0; }

/// The atanh terms left out (a geometric bound), in log2 units, at s = 3 - 2 sqrt 2.
double log2_truncation() {
    const double s = 3.0 - 2.0 * std::sqrt(2.0);
    return 2.0 * std::pow(s, 11) / (11.0 * (1.0 - s * s)) / std::log(2.0);
}

using test::Lcg;

}  // namespace

// Proven against: the last series term (-t^11 / 11) dropped (errors up to 4.6e-8 > 2.9e-9).
TEST_CASE("stable_atan2: within (2 - sqrt 3)^13 / 13 of std::atan2 in double, every octant") {
    const double truncation = atan_truncation();
    CHECK(truncation < 2.9e-9);
    // About 20 roundings, each at most half an ulp of a value below 4: 20 x 2 x 2^-52.
    const double bound = truncation + 40.0 * DBL_EPSILON;
    double worst = 0.0;
    Lcg r;
    for (int k = 0; k < 200000; ++k) {
        const double angle = (2.0 * r.next() - 1.0) * kPi;
        const double radius = std::ldexp(0.5 + r.next(), int(r.next() * 40.0) - 20);
        const double y = radius * std::sin(angle), x = radius * std::cos(angle);
        const double e = std::fabs(simd::stable_atan2(y, x) - std::atan2(y, x));
        worst = e > worst ? e : worst;
    }
    CHECK(worst <= bound);
    // Exact where the series vanishes: the axes, and atan(1/sqrt 3) = pi/6.
    CHECK(simd::stable_atan2(0.0, 1.0) == 0.0);
    CHECK(simd::stable_atan2(1.0, 0.0) == doctest::Approx(kPi / 2).epsilon(1e-15));
    CHECK(simd::stable_atan2(0.0, -1.0) == doctest::Approx(kPi).epsilon(1e-15));
    CHECK(simd::stable_atan2(-1.0, 0.0) == doctest::Approx(-kPi / 2).epsilon(1e-15));
    CHECK(simd::stable_atan2(1.0, std::sqrt(3.0)) == doctest::Approx(kPi / 6).epsilon(1e-15));
    CHECK(simd::stable_atan2(0.0, 0.0) == 0.0);
    CHECK(std::isnan(simd::stable_atan2(std::nan(""), 1.0)));
}

// Proven against: (a sqrt 3 - 1) computed as (a - sqrt 3) (errors near 1 rad).
TEST_CASE("stable_atan2 in float: within the truncation bound plus float roundings") {
    // About 20 roundings in float, each at most half an ulp of a value below 4: 20 x 2^-22.
    const double bound = atan_truncation() + 20.0 * std::ldexp(1.0, -22);
    double worst = 0.0;
    Lcg r;
    for (int k = 0; k < 200000; ++k) {
        const double angle = (2.0 * r.next() - 1.0) * kPi;
        const float y = float(std::sin(angle)), x = float(std::cos(angle));
        const double e = std::fabs(double(simd::stable_atan2(y, x)) - std::atan2(double(y), double(x)));
        worst = e > worst ? e : worst;
    }
    CHECK(worst <= bound);
}

// Proven against: the s^9 / 9 term dropped (errors up to about 4e-8 > 1.1e-9).
TEST_CASE("stable_log2: within 2 s^11 / (11 (1 - s^2) ln 2) of std::log2 in double") {
    const double truncation = log2_truncation();
    CHECK(truncation < 1.1e-9);
    double worst = 0.0;
    Lcg r;
    for (int k = 0; k < 200000; ++k) {
        const double x = std::ldexp(1.0 + r.next(), int(r.next() * 80.0) - 40);
        const double exact = std::log2(x);
        // The series part is below 1/2 (about 16 roundings of half an ulp of a value below 1),
        // then one rounding of e + it, at most half an ulp of |log2 x| + 1.
        const double bound = truncation + 16.0 * DBL_EPSILON + (std::fabs(exact) + 1.0) * DBL_EPSILON;
        const double e = std::fabs(simd::stable_log2(x) - exact) - bound;
        worst = e > worst ? e : worst;
    }
    CHECK(worst == 0.0);
    // Exactly 0 at 1 and k at 2^k (s = 0).
    CHECK(simd::stable_log2(1.0) == 0.0);
    CHECK(simd::stable_log2(1.0f) == 0.0f);
    CHECK(simd::stable_log2(8.0) == 3.0);
    CHECK(simd::stable_log2(0.25f) == -2.0f);
    CHECK(simd::stable_log2(1024.0f) == 10.0f);
}

// Proven against: the batch exponent taken without removing the bias (lanes off by 127).
TEST_CASE("stable_atan2 and stable_log2: a batch gives each lane the scalar float's bits") {
    using B = xsimd::batch<float>;
    constexpr std::size_t W = B::size;
    Lcg r;
    for (int k = 0; k < 2000; ++k) {
        alignas(64) float y[W], x[W], p[W], a[W], l[W];
        for (std::size_t i = 0; i < W; ++i) {
            y[i] = float(4.0 * r.next() - 2.0);
            x[i] = float(4.0 * r.next() - 2.0);
            p[i] = float(std::ldexp(1.0 + r.next(), int(r.next() * 60.0) - 20));
        }
        simd::stable_atan2(B::load_aligned(y), B::load_aligned(x)).store_aligned(a);
        simd::stable_log2(B::load_aligned(p)).store_aligned(l);
        for (std::size_t i = 0; i < W; ++i) {
            CHECK(test::float_bits(a[i]) == test::float_bits(simd::stable_atan2(y[i], x[i])));
            CHECK(test::float_bits(l[i]) == test::float_bits(simd::stable_log2(p[i])));
        }
    }
}
