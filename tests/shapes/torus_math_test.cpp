// Tests for engine/shapes/torus_math.h: hand-computed cases, a long-double reference on
// random rays (outside, inside the tube, inside the hole, tangent, near-tangent, far away),
// scalar/SIMD agreement and bad inputs.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "shapes/torus_math.h"

using streamrt::Vec3d;
using streamrt::torus_hit_t;
using streamrt::torus_normal;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double hit(Vec3d o, Vec3d d, double r, double tmin = 0.0, double tmax = kInf) {
    return torus_hit_t<double>(o, d, r, tmin, tmax);
}

// ---------------------------------------------------------------------------------------
// Long-double reference: march along the ray with steps bounded below by the distance to
// the surface (h_i = |dist to circle_i| - r is 1-Lipschitz, circle_1 = ring on p's side,
// circle_2 = ring point on the far side, whose zero set is the spindle's inner surface), so
// no crossing is stepped over unless the step is the minimum step; refine sign changes by
// bisection; record tangent touches and very shallow enter/exit pairs as "ambiguous".
using LD = long double;

struct LV {
    LD x, y, z;
};

struct RefResult {
    bool hit = false;
    LD t = 0;            // first root in (t_min, t_max), in units of the ray parameter
    LD cos_angle = 1;    // |cos| between the unit direction and the surface normal at t
    LD ambiguous_t = -1; // smallest t of a near-tangent feature (or -1)
};

struct RefRay {
    LV o, u;
    LD r;
    LV at(LD s) const { return {o.x + s * u.x, o.y + s * u.y, o.z + s * u.z}; }
    void h(LD s, LD& h1, LD& h2) const {
        const LV p = at(s);
        const LD rho = std::sqrt(p.x * p.x + p.z * p.z);
        h1 = std::sqrt((rho - 1) * (rho - 1) + p.y * p.y) - r;
        h2 = std::sqrt((rho + 1) * (rho + 1) + p.y * p.y) - r;
    }
    LD hk(LD s, int k) const {
        LD a, b;
        h(s, a, b);
        return k == 0 ? a : b;
    }
};

RefResult reference(const Vec3d& o_, const Vec3d& d_, double r_, double tmin, double tmax) {
    RefResult res;
    RefRay ray;
    const LV d{d_.x, d_.y, d_.z};
    const LD L = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    ray.o = {o_.x, o_.y, o_.z};
    ray.u = {d.x / L, d.y / L, d.z / L};
    ray.r = r_;
    const LD B = 1 + ray.r;
    const LD b = ray.o.x * ray.u.x + ray.o.y * ray.u.y + ray.o.z * ray.u.z;
    const LV pc = ray.at(-b);
    const LD h2c = pc.x * pc.x + pc.y * pc.y + pc.z * pc.z;
    if (h2c > B * B * (1 + 1e-12L)) return res;
    const LD w = std::sqrt(std::max<LD>(B * B - h2c, 0)) + 1e-9L;
    LD s0 = std::max<LD>(-b - w, LD(tmin) * L);
    const LD s1 = std::min<LD>(-b + w, std::isinf(tmax) ? LD(1e300) : LD(tmax) * L);
    if (s0 > s1) return res;
    const LD tau = 1e-11L + 1e-14L * std::sqrt(ray.o.x * ray.o.x + ray.o.y * ray.o.y + ray.o.z * ray.o.z);
    const LD min_step = 1e-7L;

    struct Root {
        LD s;
        int k;
    };
    std::vector<Root> roots;
    LD amb = -1;
    auto note_amb = [&](LD s) {
        if (amb < 0 || s < amb) amb = s;
    };
    LD s = s0, h1, h2;
    ray.h(s, h1, h2);
    LD hm_prev2 = kInf, hm_prev = kInf;  // min(|h1|,|h2|) at the two previous samples
    LD s_prev = s;
    bool crossed_prev = false;
    while (s < s1) {
        const LD hm = std::min(std::fabs(h1), std::fabs(h2));
        const LD step = std::max(hm, min_step);
        const LD sn = std::min(s + step, s1);
        LD n1, n2;
        ray.h(sn, n1, n2);
        bool crossed = false;
        for (int k = 0; k < 2; ++k) {
            const LD ha = k == 0 ? h1 : h2, hb = k == 0 ? n1 : n2;
            if ((ha < 0) != (hb < 0)) {
                LD lo = s, hi = sn;
                const bool neg_lo = ha < 0;
                for (int it = 0; it < 200 && hi - lo > 0; ++it) {
                    const LD mid = (lo + hi) / 2;
                    if (mid <= lo || mid >= hi) break;
                    if ((ray.hk(mid, k) < 0) == neg_lo) lo = mid; else hi = mid;
                }
                roots.push_back({(lo + hi) / 2, k});
                crossed = true;
            }
        }
        // Touch: a local minimum of the distance bound below tau without any crossing.
        if (!crossed && !crossed_prev && hm_prev < tau && hm_prev <= hm_prev2 && hm_prev <= hm) note_amb(s_prev);
        hm_prev2 = hm_prev;
        hm_prev = hm;
        s_prev = s;
        crossed_prev = crossed;
        s = sn;
        h1 = n1;
        h2 = n2;
    }
    std::sort(roots.begin(), roots.end(), [](const Root& a, const Root& b) { return a.s < b.s; });
    // Shallow pairs: two consecutive crossings with the surface barely entered in between,
    // or roots that coincide (the spindle's singular points).
    for (size_t i = 0; i + 1 < roots.size(); ++i) {
        const LD mid = (roots[i].s + roots[i + 1].s) / 2;
        LD a, c;
        ray.h(mid, a, c);
        if (std::min(std::fabs(a), std::fabs(c)) < tau || roots[i + 1].s - roots[i].s < 1e-9L) {
            note_amb(roots[i].s);
        }
    }
    const LD smin = LD(tmin) * L;
    for (const Root& rt : roots) {
        if (rt.s > smin && rt.s < s1) {
            res.hit = true;
            res.t = rt.s / L;
            // Normal of factor k's surface: p - (+-) ring point.
            const LV p = ray.at(rt.s);
            const LD rho = std::sqrt(p.x * p.x + p.z * p.z);
            const LD sg = rt.k == 0 ? 1 : -1;
            const LV n{p.x - (rho > 0 ? sg * p.x / rho : 0), p.y, p.z - (rho > 0 ? sg * p.z / rho : 0)};
            const LD nl = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
            res.cos_angle = nl > 0 ? std::fabs(n.x * ray.u.x + n.y * ray.u.y + n.z * ray.u.z) / nl : 0;
            break;
        }
    }
    // Sampled features are located to within a few minimum steps.
    res.ambiguous_t = amb < 0 ? -1 : std::max<LD>(amb - 4 * min_step, 0) / L;
    return res;
}

// ---------------------------------------------------------------------------------------
// Random rays.
struct Ray {
    Vec3d o, d;
    double tmin = 0, tmax = kInf;
};

struct Gen {
    std::mt19937_64 rng;
    explicit Gen(uint64_t seed) : rng(seed) {}
    double u(double a = 0, double b = 1) { return std::uniform_real_distribution<double>(a, b)(rng); }
    Vec3d unit() {
        for (;;) {
            Vec3d v{u(-1, 1), u(-1, 1), u(-1, 1)};
            const double l2 = dot(v, v);
            if (l2 > 1e-4 && l2 <= 1) return v * (1 / std::sqrt(l2));
        }
    }
    double scale() { return std::pow(10.0, u(-2, 2)); }
    // Point of the solid at tube fraction a (a = 1: surface); also its outward normal.
    Vec3d tube_point(double r, double a, Vec3d* normal = nullptr) {
        const double phi = u(0, 2 * M_PI), th = u(0, 2 * M_PI);
        const double rho = 1 + r * a * std::cos(phi), y = r * a * std::sin(phi);
        if (normal) *normal = Vec3d{std::cos(phi) * std::cos(th), std::sin(phi), std::cos(phi) * std::sin(th)};
        return {rho * std::cos(th), y, rho * std::sin(th)};
    }
    Vec3d box_target(double r) {
        const double B = 1 + r;
        return {u(-B, B), u(-r, r), u(-B, B)};
    }
    Vec3d perp(const Vec3d& n) {
        const Vec3d v = unit();
        const Vec3d t = v - n * dot(v, n);
        return t * (1 / std::sqrt(dot(t, t)));
    }
    Ray make(int category, double r) {
        Ray ray;
        const double B = 1 + r;
        switch (category) {
            case 0: {  // outside, aimed into the bounding box
                ray.o = unit() * u(B, 4 * B);
                ray.d = (box_target(r) - ray.o) * scale();
                break;
            }
            case 1: {  // inside the tube
                ray.o = tube_point(r, std::sqrt(u()) * 0.999);
                ray.d = unit() * scale();
                break;
            }
            case 2: {  // inside the hole (r < 1) or the spindle's inner lemon (r > 1)
                for (;;) {
                    const double rho = u(0, std::fabs(1 - r)), y = u(-1.5 * r, 1.5 * r), th = u(0, 2 * M_PI);
                    if (r > 1 && (rho + 1) * (rho + 1) + y * y >= r * r) continue;
                    ray.o = {rho * std::cos(th), y, rho * std::sin(th)};
                    break;
                }
                ray.d = unit() * scale();
                break;
            }
            case 3:    // tangent at a surface point
            case 4: {  // near-tangent: offset along the normal by +-1e-10 .. 1e-3
                Vec3d n;
                const Vec3d p = tube_point(r, 1, &n);
                const Vec3d t = perp(n);
                ray.o = p - t * u(0.5, 4);
                if (category == 4) ray.o = ray.o + n * ((u() < 0.5 ? -1 : 1) * std::pow(10.0, u(-10, -3)));
                ray.d = t * scale();
                break;
            }
            default: {  // far away (|o| ~ 1e4), aimed at the box or at a tangent point
                ray.o = unit() * (1e4 * u(1, 1.5));
                Vec3d target = box_target(r);
                if (u() < 0.3) {
                    target = tube_point(r, 1);  // aim at a surface point (often grazing)
                }
                ray.d = (target - ray.o) * scale();
                break;
            }
        }
        if (u() < 0.1) ray.tmax = u(0, 2 * std::sqrt(dot(ray.o, ray.o)) + 2 * B) / std::sqrt(dot(ray.d, ray.d));
        return ray;
    }
};

uint64_t test_seed() {
    if (const char* s = std::getenv("STREAMRT_SEED")) return std::strtoull(s, nullptr, 10);
    return 20240611ULL;
}

constexpr double kRadii[] = {1e-3, 0.25, 0.9, 1.5};
constexpr int kCategories = 6;
const char* const kCategoryNames[kCategories] = {"outside", "in-tube", "in-hole", "tangent", "near-tangent", "far"};

}  // namespace

TEST_CASE("torus_hit_t: hand-computed cases") {
    // From (0,0,5) along -z: outer equator at z = 1.25.
    CHECK(hit({0, 0, 5}, {0, 0, -1}, 0.25) == doctest::Approx(3.75).epsilon(1e-14));
    // Non-unit direction: t scales.
    CHECK(hit({0, 0, 5}, {0, 0, -2}, 0.25) == doctest::Approx(1.875).epsilon(1e-14));
    const Vec3d n = torus_normal(Vec3d{0, 0, 1.25}, 0.25);
    CHECK(n.x == doctest::Approx(0));
    CHECK(n.y == doctest::Approx(0));
    CHECK(n.z / std::sqrt(dot(n, n)) == doctest::Approx(1));
    // Down the y axis through the hole.
    CHECK(hit({0, 5, 0}, {0, -1, 0}, 0.25) == kInf);
    CHECK(hit({0, -5, 0}, {0, 1, 0}, 0.9) == kInf);
    // From (3,0,0) along -x.
    CHECK(hit({3, 0, 0}, {-1, 0, 0}, 0.25) == doctest::Approx(3 - 1.25).epsilon(1e-14));
    // Inside the tube, exiting.
    CHECK(hit({1, 0, 0}, {1, 0, 0}, 0.25) == doctest::Approx(0.25).epsilon(1e-14));
    CHECK(hit({1, 0, 0}, {-1, 0, 0}, 0.25) == doctest::Approx(0.25).epsilon(1e-14));
    // t range: the first hit at 3.75 is excluded, the next one (inner wall at z = 0.75) is not.
    CHECK(hit({0, 0, 5}, {0, 0, -1}, 0.25, 3.8) == doctest::Approx(4.25).epsilon(1e-14));
    CHECK(hit({0, 0, 5}, {0, 0, -1}, 0.25, 0.0, 3.7) == kInf);
    // Grazing the top (y = r): a hit near the tangent point x = +-1 or a miss, never NaN.
    for (double y : {0.25, std::nextafter(0.25, 0.0), std::nextafter(0.25, 1.0)}) {
        const double t = hit({-5, y, 0}, {1, 0, 0}, 0.25);
        CHECK(!std::isnan(t));
        if (t != kInf) CHECK(std::fabs(t - 4) < 1e-4);
    }
    // Edge-on ray in the plane y = 0 along x = 0.75: touches the inner equator at z = 0 but
    // first crosses the tube, entering at z = -1.
    CHECK(hit({0.75, 0, -5}, {0, 0, 1}, 0.25) == doctest::Approx(4).epsilon(1e-14));
    // Edge-on ray tangent to the outer equator (x = 1.25): a hit at z = 0 or a miss.
    {
        const double t = hit({1.25, 0, -5}, {0, 0, 1}, 0.25);
        CHECK(!std::isnan(t));
        if (t != kInf) CHECK(std::fabs(t - 5) < 1e-4);
    }
    // Spindle r = 1.5: outer surface at z = 2.5.
    CHECK(hit({0, 0, 5}, {0, 0, -1}, 1.5) == doctest::Approx(2.5).epsilon(1e-14));
    // ... next the inner "lemon" surface at z = 0.5.
    CHECK(hit({0, 0, 5}, {0, 0, -1}, 1.5, 2.6) == doctest::Approx(4.5).epsilon(1e-14));
    // Thin tube r = 1e-3 head-on.
    CHECK(hit({0, 0, 5}, {0, 0, -1}, 1e-3) == doctest::Approx(5 - 1.001).epsilon(1e-14));
    // Far origin.
    CHECK(hit({0, 0, 1e4}, {0, 0, -1}, 0.25) == doctest::Approx(1e4 - 1.25).epsilon(1e-15));
}

TEST_CASE("torus_hit_t: bad inputs give a miss, never NaN") {
    using B = xsimd::batch<double, xsimd::default_arch>;
    const double den = std::numeric_limits<double>::denorm_min();
    const double bad[] = {kNaN, kInf, -kInf};
    std::vector<Ray> rays;
    for (double v : bad) {
        rays.push_back({{v, 0, 5}, {0, 0, -1}});
        rays.push_back({{0, 0, 5}, {0, v, -1}});
    }
    rays.push_back({{0, 0, 5}, {0, 0, -1}, kNaN, kInf});
    rays.push_back({{0, 0, 5}, {0, 0, -1}, kInf, kInf});
    rays.push_back({{0, 0, 5}, {0, 0, -1}, 0.0, -kInf});
    rays.push_back({{0, 0, 5}, {0, 0, -1}, 0.0, kNaN});
    rays.push_back({{0, 0, 5}, {0, 0, 0}});                  // zero direction
    rays.push_back({{0, 0, 5}, {0, 0, -den}});               // denormal direction
    rays.push_back({{0, 0, 5}, {den, -den, den}});           // denormal direction
    rays.push_back({{den, den, 5}, {0, 0, -0.0}});           // zero direction
    for (const Ray& ray : rays) {
        const double t = hit(ray.o, ray.d, 0.25, ray.tmin, ray.tmax);
        CHECK(t == kInf);
    }
    // An infinite t range is fine: t_min = -inf still finds the first root (3.75).
    CHECK(hit({0, 0, 5}, {0, 0, -1}, 0.25, -kInf, kInf) == doctest::Approx(3.75));
    // Bad minor radius.
    for (double r : {kNaN, kInf, 0.0, -0.25, den}) CHECK(hit({0, 0, 5}, {0, 0, -1}, r) == kInf);
    // The same through the SIMD lanes, mixed with a good lane.
    constexpr size_t N = B::size;
    for (size_t base = 0; base < rays.size(); base += N - 1) {
        alignas(64) double v[9][N];
        for (size_t l = 0; l < N; ++l) {
            const Ray ray = l == 0 ? Ray{{0, 0, 5}, {0, 0, -1}} : rays[std::min(base + l - 1, rays.size() - 1)];
            const double vals[9] = {ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z, 0.25, ray.tmin, ray.tmax};
            for (int k = 0; k < 9; ++k) v[k][l] = vals[k];
        }
        auto ld = [&](int k) { return B::load_aligned(v[k]); };
        const B t = torus_hit_t<B>({ld(0), ld(1), ld(2)}, {ld(3), ld(4), ld(5)}, ld(6), ld(7), ld(8));
        alignas(64) double out[N];
        t.store_aligned(out);
        CHECK(out[0] == doctest::Approx(3.75));
        for (size_t l = 1; l < N; ++l) CHECK(out[l] == kInf);
    }
}

TEST_CASE("torus_hit_t: random rays against a long-double reference, scalar and SIMD") {
    using B = xsimd::batch<double, xsimd::default_arch>;
    constexpr size_t N = B::size;
    const uint64_t seed = test_seed();
    MESSAGE("torus reference seed = " << seed << " (override with STREAMRT_SEED)");
    CAPTURE(seed);
    Gen gen(seed);
    const int per_category = 4500;  // 4 radii x 6 categories x 4500 = 108000 rays

    size_t total = 0, total_amb_disagree = 0;
    double max_rel_all = 0, max_rel_clean = 0, max_rel_clean_dist = 0, max_simd_rel = 0;
    size_t simd_mismatch = 0, nan_count = 0;
    for (double r : kRadii) {
        for (int cat = 0; cat < kCategories; ++cat) {
            std::vector<Ray> rays(per_category);
            for (Ray& ray : rays) ray = gen.make(cat, r);
            std::vector<double> ts(rays.size());
            size_t hits = 0, amb_disagree = 0, bad_disagree = 0;
            double max_rel = 0, max_rel_c = 0, max_rel_cd = 0, worst_cos = 1;
            for (size_t i = 0; i < rays.size(); ++i) {
                const Ray& ray = rays[i];
                const double t = hit(ray.o, ray.d, r, ray.tmin, ray.tmax);
                ts[i] = t;
                if (std::isnan(t)) ++nan_count;
                const RefResult ref = reference(ray.o, ray.d, r, ray.tmin, ray.tmax);
                const bool agree_hit = (t != kInf) == ref.hit;
                double rel = 0;
                if (agree_hit && ref.hit) rel = double(std::fabs(LD(t) - ref.t) / ref.t);
                const bool ok = agree_hit && rel < 1e-6;
                if (!ok) {
                    // Allowed only at a near-tangent feature not after both answers.
                    const LD lim = std::max<LD>(t == kInf ? 0 : LD(t), ref.hit ? ref.t : 0) * (1 + 1e-9L);
                    const bool in_band = ref.ambiguous_t >= 0 && ref.ambiguous_t <= lim + 1e-12L;
                    if (in_band) {
                        ++amb_disagree;
                    } else {
                        ++bad_disagree;
                        if (bad_disagree <= 5) {
                            MESSAGE("disagreement r=" << r << " cat=" << std::string(kCategoryNames[cat]) << " o=(" << ray.o.x
                                                      << "," << ray.o.y << "," << ray.o.z << ") d=(" << ray.d.x << ","
                                                      << ray.d.y << "," << ray.d.z << ") tmax=" << ray.tmax << " t=" << t
                                                      << " ref=" << (ref.hit ? double(ref.t) : kInf)
                                                      << " amb=" << double(ref.ambiguous_t));
                        }
                    }
                    continue;
                }
                if (ref.hit) {
                    ++hits;
                    max_rel = std::max(max_rel, rel);
                    if (ref.cos_angle >= 1e-3L) {
                        max_rel_c = std::max(max_rel_c, rel);
                        if (t * std::sqrt(dot(ray.d, ray.d)) >= 1e-2) max_rel_cd = std::max(max_rel_cd, rel);
                    }
                    worst_cos = std::min(worst_cos, double(ref.cos_angle));
                }
            }
            // SIMD lanes must reproduce the scalar results (misses included).
            for (size_t base = 0; base < rays.size(); base += N) {
                alignas(64) double v[8][N];
                for (size_t l = 0; l < N; ++l) {
                    const Ray& ray = rays[std::min(base + l, rays.size() - 1)];
                    const double vals[8] = {ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z, ray.tmin, ray.tmax};
                    for (int k = 0; k < 8; ++k) v[k][l] = vals[k];
                }
                auto ld = [&](int k) { return B::load_aligned(v[k]); };
                const B t = torus_hit_t<B>({ld(0), ld(1), ld(2)}, {ld(3), ld(4), ld(5)}, B(r), ld(6), ld(7));
                alignas(64) double out[N];
                t.store_aligned(out);
                for (size_t l = 0; l < N && base + l < rays.size(); ++l) {
                    const double ts_ = ts[base + l];
                    if (ts_ == kInf || out[l] == kInf) {
                        if (ts_ != out[l]) ++simd_mismatch;
                    } else {
                        max_simd_rel = std::max(max_simd_rel, std::fabs(out[l] - ts_) / std::fabs(ts_));
                    }
                }
            }
            MESSAGE("r=" << r << " " << std::string(kCategoryNames[cat]) << ": rays=" << rays.size() << " hits=" << hits
                         << " max_rel=" << max_rel << " max_rel(|cos|>=1e-3)=" << max_rel_c
                         << " max_rel(|cos|>=1e-3,dist>=1e-2)=" << max_rel_cd
                         << " min|cos|=" << worst_cos << " tangent-band disagreements=" << amb_disagree
                         << " other disagreements=" << bad_disagree);
            CHECK(bad_disagree == 0);
            // Exactly tangent rays (category 3) sit in the band by construction; elsewhere the
            // band must stay tiny (at most 0.2% of the rays).
            if (cat != 3) CHECK(amb_disagree <= rays.size() / 500);
            total += rays.size();
            total_amb_disagree += amb_disagree;
            max_rel_all = std::max(max_rel_all, max_rel);
            max_rel_clean = std::max(max_rel_clean, max_rel_c);
            max_rel_clean_dist = std::max(max_rel_clean_dist, max_rel_cd);
        }
    }
    MESSAGE("torus double: rays=" << total << " max relative t error=" << max_rel_all
                                  << " (non-grazing |cos|>=1e-3: " << max_rel_clean
                                  << "; and hit distance >= 1e-2: " << max_rel_clean_dist
                                  << ") tangent-band disagreements=" << total_amb_disagree
                                  << " SIMD vs scalar max rel=" << max_simd_rel << " SIMD hit/miss mismatches="
                                  << simd_mismatch);
    CHECK(total >= 100000);
    CHECK(nan_count == 0);
    // Grazing hits (|cos| < 1e-3) are ill-conditioned (error ~ eps/|cos| up to sqrt(eps)); hits
    // a tiny distance from the origin carry the absolute error ~1e-16 of coordinates of size 1.
    CHECK(max_rel_all < 1e-6);
    CHECK(max_rel_clean < 1e-10);
    CHECK(max_rel_clean_dist < 1e-12);
    CHECK(simd_mismatch == 0);
    CHECK(max_simd_rel <= 1e-12);
}

// ---------------------------------------------------------------------------------------
// The torus as a CSG solid (torus_spans): the tube's inside along the whole line.

TEST_CASE("torus_spans: along the x axis the tube's two spans, none through the hole") {
    using streamrt::torus_spans;
    // R = 1, r = 0.5: the axis y = z = 0 crosses the tube at x = -1.5, -0.5, 0.5, 1.5.
    const auto s = torus_spans<double>({-5, 0, 0}, {2, 0, 0}, 0.5);  // t in units of |d| = 2
    CHECK(s[0].enter == doctest::Approx(1.75).epsilon(1e-12));
    CHECK(s[0].exit == doctest::Approx(2.25).epsilon(1e-12));
    CHECK(s[1].enter == doctest::Approx(2.75).epsilon(1e-12));
    CHECK(s[1].exit == doctest::Approx(3.25).epsilon(1e-12));
    // Over the whole line: an origin past the torus sees the same spans behind it.
    const auto back = torus_spans<double>({5, 0, 0}, {1, 0, 0}, 0.5);
    CHECK(back[0].enter == doctest::Approx(-6.5).epsilon(1e-12));
    CHECK(back[1].exit == doctest::Approx(-3.5).epsilon(1e-12));
    // Down the axis of the ring, through the hole: nothing. Through the tube's top at
    // x = 1 straight down: one span, |y| <= 0.5.
    const auto hole = torus_spans<double>({0, 3, 0}, {0, -1, 0}, 0.5);
    CHECK(!(hole[0].enter < hole[0].exit));
    CHECK(!(hole[1].enter < hole[1].exit));
    const auto top = torus_spans<double>({1, 3, 0}, {0, -1, 0}, 0.5);
    CHECK(top[0].enter == doctest::Approx(2.5).epsilon(1e-12));
    CHECK(top[0].exit == doctest::Approx(3.5).epsilon(1e-12));
    CHECK(!(top[1].enter < top[1].exit));
}

TEST_CASE("torus_spans: random lines against the long-double reference, SIMD lanes to the bit") {
    using streamrt::SpanT;
    using streamrt::torus_spans;
    using B = xsimd::batch<double, xsimd::default_arch>;
    constexpr size_t N = B::size;
    Gen gen(test_seed() + 7);
    size_t checked = 0, crossings = 0, four = 0;
    for (double r : {1e-3, 0.25, 0.9, 1.0}) {
        for (int cat : {0, 1, 2, 5}) {
            std::vector<Ray> rays(1200);
            for (Ray& ray : rays) ray = gen.make(cat, r);
            std::vector<std::array<SpanT<double>, 2>> spans(rays.size());
            for (size_t i = 0; i < rays.size(); ++i) {
                const Ray& ray = rays[i];
                spans[i] = torus_spans<double>(ray.o, ray.d, r);
                // Every crossing of the line, in order, from the reference run again past each.
                // The line's scale: the torus's size in units of t.
                const double size = (1 + r) / std::sqrt(dot(ray.d, ray.d));
                std::vector<double> ref;
                bool ambiguous = false;
                double from = -kInf;
                while (ref.size() < 5) {
                    const RefResult h = reference(ray.o, ray.d, r, from, kInf);
                    ambiguous = ambiguous || h.ambiguous_t >= 0;
                    if (!h.hit) break;
                    ref.push_back(double(h.t));
                    from = double(h.t) + 1e-10 * (std::fabs(double(h.t)) + size);
                }
                if (ambiguous) continue;  // a grazing touch somewhere on the line
                std::vector<double> got;
                for (const SpanT<double>& s : spans[i]) {
                    if (!(s.enter < s.exit)) continue;
                    got.push_back(s.enter);
                    got.push_back(s.exit);
                }
                CAPTURE(r);
                CAPTURE(cat);
                CAPTURE(i);
                CAPTURE(got);
                CAPTURE(ref);
                REQUIRE(got.size() == ref.size());
                for (size_t k = 0; k < got.size(); ++k)
                    CHECK(std::fabs(got[k] - ref[k]) <= 1e-7 * (std::fabs(ref[k]) + size));
                ++checked;
                crossings += got.size();
                four += got.size() == 4 ? 1 : 0;
            }
            // SIMD lanes give each line the scalar spans, bit for bit.
            for (size_t base = 0; base < rays.size(); base += N) {
                alignas(64) double v[6][N];
                for (size_t l = 0; l < N; ++l) {
                    const Ray& ray = rays[std::min(base + l, rays.size() - 1)];
                    const double vals[6] = {ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z};
                    for (int k = 0; k < 6; ++k) v[k][l] = vals[k];
                }
                const auto ld = [&](int k) { return B::load_aligned(v[k]); };
                const auto s = torus_spans<B>({ld(0), ld(1), ld(2)}, {ld(3), ld(4), ld(5)}, B(r));
                alignas(64) double out[4][N];
                s[0].enter.store_aligned(out[0]);
                s[0].exit.store_aligned(out[1]);
                s[1].enter.store_aligned(out[2]);
                s[1].exit.store_aligned(out[3]);
                for (size_t l = 0; l < N && base + l < rays.size(); ++l) {
                    const auto& want = spans[base + l];
                    CHECK(std::memcmp(&out[0][l], &want[0].enter, sizeof(double)) == 0);
                    CHECK(std::memcmp(&out[1][l], &want[0].exit, sizeof(double)) == 0);
                    CHECK(std::memcmp(&out[2][l], &want[1].enter, sizeof(double)) == 0);
                    CHECK(std::memcmp(&out[3][l], &want[1].exit, sizeof(double)) == 0);
                }
            }
        }
    }
    MESSAGE("torus_spans: lines checked " << checked << ", crossings " << crossings << ", lines crossing four times "
                                          << four);
    CHECK(checked >= 10000);
    CHECK(four >= 500);
}
