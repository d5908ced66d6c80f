#pragma once
// Adaptive sampling's rules, shared by both engines (docs/adaptive-sampling.md): the rounds a
// pixel's samples come in, the tally of its samples, its error estimate and the decision to
// take another round. Every decision reads the pixel's own samples only, so the picture is
// the same whatever renders the pixel's neighbours: any -j, tile order, shard or MPI rank.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/vec_lanes.h"
#include "render/sampling.h"

namespace streamrt {

/// The cap (spp) of an adaptive render whose scene and command line say spp 1 (or nothing).
inline constexpr int kDefaultAdaptiveCap = 64;

/// Samples of every pixel's first round: enough for a first spread (3 degrees of freedom),
/// few enough that flat pixels cost little. With a cap of at least 4 they are the pixel's
/// four corners (corner_rounds), each shared with the neighbours: about one ray per pixel.
inline constexpr int kFirstRoundSamples = 4;

/// Round r of a pixel whose cap is `cap` samples (--spp): the first takes
/// min(cap, kFirstRoundSamples) samples, each later one as many as the pixel holds
/// (doubling), the last cut at the cap. count 0: there is no round r. The rounds are runs of
/// the pixel's sequence (SampleRun::sequence): round r >= 1 of a cap of at least 8 is the
/// aligned block [2^(r+1), 2^(r+2)), so a pixel that stops after any round is evenly covered.
inline SampleRun adaptive_round(int r, int cap) {
    int first = 0, count = std::min(cap, kFirstRoundSamples);
    for (int i = 0; i < r && count > 0; ++i) {
        first += count;
        count = std::min(first, cap - first);
    }
    return {.first = first, .count = std::max(count, 0), .sequence = true};
}

/// Rec. 709 luminance of linear RGB: what the image's estimate (image_error_squared) compares.
inline double luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

/// What one corner sample weighs in a pixel's mean, against 1 for a sample of the pixel's own
/// sequence: a corner ray is shared by the four pixels it bounds, and the four corners together
/// count as half a sample. They sit on the pixel's border, a 2 x 2 grid that places an edge far
/// less well than the pixel's own stratified points; at equal weight they were half the error
/// of the refined pixels on whitted.cfg. The weight changes no decision (the spread counts
/// every sample alike), only the pixel's value. Measured at uniform 16 spp's error (rays
/// traced, docs/adaptive-sampling.md, "How the samples are taken"), with the spread per
/// channel, weights 1/2, 1/4, 1/8 and 1/16: whitted 0.366, 0.309, 0.299, 0.298 of uniform 16's
/// rays; textured 0.376, 0.295, 0.275, 0.274; soft shadows (whose error is the area light's
/// noise, which a corner averages as well as any sample) 0.129 at 1/4, 0.139 at 1/8.
inline constexpr double kCornerWeight = 0.125;

/// A pixel's samples so far: their colour sum (each corner weighted kCornerWeight), and per
/// channel the sums of the samples and of their squares taken about the first sample (the
/// shifted-data form: in a bright flat pixel the sums stay small, so the variance is not lost
/// to cancellation, and no division per sample). The spread is the mean of the three
/// channels' variances, as the image's RMSE is the mean of its channels' squared errors: a
/// spread of luminance alone did not see samples of different colour and equal luminance
/// (the edge of a red and a green square, a coloured highlight), and such pixels stopped at
/// their corners with an error of 0.1 - 0.2 in one channel (docs/adaptive-sampling.md,
/// "What T means"). The spread and its decisions count every sample alike, corners included:
/// a corner that disagrees is the first sign of an edge.
struct PixelTally {
    double r = 0, g = 0, b = 0;  ///< colour sums, corners weighted
    double shift[3] = {0, 0, 0};  ///< the first sample's R, G, B
    double sum[3] = {0, 0, 0}, sum_sq[3] = {0, 0, 0};  ///< sums of c - shift and of its square, per channel
    double sum_y_before = 0;  ///< sum_y() before the latest round (begin_round)
    double corner_y = 0;      ///< the corners' share of sum_y()
    int n = 0;
    std::uint16_t n_before = 0;  ///< n before the latest round (at most half the cap, 32768); 0 while in the first
    std::uint16_t corners = 0;   ///< how many of the n samples are corners (add_corner): 0 or 4

    /// Marks the start of a round: its samples are compared with those before it
    /// (image_error_squared).
    void begin_round() { n_before = std::uint16_t(n), sum_y_before = sum_y(); }

    /// A sample of the pixel's own sequence.
    void add(float sr, float sg, float sb) {
        r += sr, g += sg, b += sb;
        add_spread(sr, sg, sb);
    }
    /// A sample at one of the pixel's corners (the corner round), weighted kCornerWeight.
    void add_corner(float sr, float sg, float sb) {
        r += kCornerWeight * sr, g += kCornerWeight * sg, b += kCornerWeight * sb;
        corner_y += add_spread(sr, sg, sb);
        ++corners;
    }
    /// The weight in the pixel's mean of its first `count` samples (the corners come first).
    double weight(int count) const { return (count - corners) + kCornerWeight * corners; }
    /// The pixel's value: the weighted mean of its samples.
    ColorT<double> mean() const {
        if (n == 0) return {0, 0, 0};
        const double w = weight(n);
        return {r / w, g / w, b / w};
    }
    /// The samples' luminance summed about the first sample's (luminance is linear).
    double sum_y() const { return luminance(sum[0], sum[1], sum[2]); }
    /// n (n - 1) s^2 with s^2 the mean over R, G and B of the channels' unbiased sample
    /// variances (n sum_sq - sum^2 per channel).
    double scaled_variance() const { return channels_scaled_variance(n, sum, sum_sq); }
    /// scaled_variance() from the per-channel sums of n samples (shared with CornerQuad).
    static double channels_scaled_variance(int n, const double sum[3], const double sum_sq[3]) {
        double v = 0;
        for (int c = 0; c < 3; ++c) v += std::max(0.0, n * sum_sq[c] - sum[c] * sum[c]);
        return v / 3;
    }
    /// standard_error() squared from scaled_variance() of n samples; 0 below 2 samples.
    static double spread_error_squared(double scaled_variance, int n) {
        return n < 2 ? 0.0 : scaled_variance / (double(n) * n * (n - 1));
    }
    /// The estimated standard error of the pixel's mean, sqrt(s^2 / n) with s^2 as in
    /// scaled_variance(): the root mean square over the channels; infinity below 2 samples
    /// (no spread yet). Stratified samples vary less than independent ones, so this errs on
    /// the high side.
    double standard_error() const {
        if (n < 2) return std::numeric_limits<double>::infinity();
        return std::sqrt(spread_error_squared(scaled_variance(), n));
    }
    /// The pixel's share of the image's estimated squared error (AdaptiveSummary's
    /// estimated_rmse). After a round that doubled the pixel's samples, the samples before it
    /// (weighted mean A, weight W) and the round's (mean B, m samples) are two estimates of
    /// the pixel, and the pixel's mean is their mean weighted by W and m; for estimates whose
    /// variances go as 1/W and 1/m, (A - B)^2 W m / (W + m)^2 estimates its squared error
    /// ((A - B)^2 / 4 for equal halves), on the luminance. Unlike standard_error()^2 it sees
    /// what stratification gains (the sequence's halves fill each other's gaps, so the
    /// pixel's mean varies far less than s^2 / n on an edge) and what the corners miss. It is
    /// one degree of freedom per pixel: too noisy to decide a pixel's rounds, sound summed
    /// over an image. Otherwise (the first round, a round cut at the cap): standard_error()^2,
    /// the channels' mean (so a pixel that stopped at its corners counts its colour spread as
    /// its decision did), 0 below 2 samples.
    double image_error_squared() const {
        if (n_before >= 2 && n == 2 * n_before) {
            const double m = n - n_before;
            // Before the round: its own samples and its corners (all of the round's are its own).
            const double w = weight(n_before);
            const double a = (sum_y_before - corner_y + kCornerWeight * corner_y) / w;
            const double d = (sum_y() - sum_y_before) / m - a;
            return d * d * w * m / ((w + m) * (w + m));
        }
        return spread_error_squared(scaled_variance(), n);
    }

private:
    /// Adds a sample to the spread's sums; returns its luminance about the first sample's.
    double add_spread(double sr, double sg, double sb) {
        const double c[3] = {sr, sg, sb};
        if (n++ == 0) shift[0] = sr, shift[1] = sg, shift[2] = sb;
        double d[3];
        for (int k = 0; k < 3; ++k) {
            d[k] = c[k] - shift[k];
            sum[k] += d[k], sum_sq[k] += d[k] * d[k];
        }
        return luminance(d[0], d[1], d[2]);
    }
};

/// A pixel that holds its four corners only (the corner round), without a PixelTally: the
/// sums add_corner makes, in its order (top left, top right, bottom left, bottom right), so
/// the same bits for mean(), the rule's above() and image_error_squared(). The neighbour rule
/// and the final pass read every pixel this way: most pixels stop at their corners, and a
/// 120-byte tally built and read for each of them was most of the final pass (whitted.cfg at
/// 640x480, -j2: final pass 3.2 -> 2.6 ms; whole process 0.983x, textured 0.966x).
struct CornerQuad {
    double colour[3];           ///< the corners' colour sums, each weighted kCornerWeight
    double sum[3], sum_sq[3];   ///< per channel, about the first corner (PixelTally's sums)
    static constexpr int n = 4;

    /// The corners c[0 .. 4), 3 floats each; `colour` summed only when `with_colour` (without
    /// it, 0: the neighbour rule needs the spread alone).
    template <bool with_colour = true>
    static CornerQuad of(const float* c0, const float* c1, const float* c2, const float* c3) {
        CornerQuad q;
        if constexpr (!with_colour) q.colour[0] = q.colour[1] = q.colour[2] = 0;
        for (int k = 0; k < 3; ++k) {
            const double shift = c0[k];
            double s = 0, s2 = 0;
            for (const float* c : {c0, c1, c2, c3}) {
                const double d = double(c[k]) - shift;
                s += d, s2 += d * d;
            }
            q.sum[k] = s, q.sum_sq[k] = s2;
            if constexpr (with_colour) {
                double w = 0;
                for (const float* c : {c0, c1, c2, c3}) w += kCornerWeight * c[k];
                q.colour[k] = w;
            }
        }
        return q;
    }
    double scaled_variance() const { return PixelTally::channels_scaled_variance(n, sum, sum_sq); }
    double image_error_squared() const { return PixelTally::spread_error_squared(scaled_variance(), n); }
    double standard_error() const { return std::sqrt(image_error_squared()); }
    ColorT<double> mean() const {
        const double w = kCornerWeight * n;  // PixelTally::weight(4) of 4 corners, exactly
        return {colour[0] / w, colour[1] / w, colour[2] / w};
    }
};

/// The sample count at which a pixel stops at a standard error of exactly T
/// (AdaptiveRule::above), and that count to the power 3/2 (its stopping point T (n / 16)^(3/4), squared).
inline constexpr double kThresholdSamples = 16;
inline constexpr double kThresholdPower = 64;
static_assert(kThresholdPower * kThresholdPower == kThresholdSamples * kThresholdSamples * kThresholdSamples);

/// What adaptive sampling is asked for: `image adaptive=T` or --adaptive T, --spp as the cap.
struct AdaptiveRule {
    double threshold = 0;  ///< T: see above(); 0: uniform sampling
    int cap = 1;           ///< the most samples a pixel takes

    bool on() const { return threshold > 0; }
    /// Whether round 0 takes the pixels' corners (render/sampling.h's corner_run): each
    /// corner is traced once and counts as a sample of each pixel it bounds, so the first
    /// round costs about one ray per pixel instead of four. A cap below 4 cannot hold the
    /// four corners; its first round is min(cap, 4) points of the pixel's sequence.
    bool corner_round() const { return cap >= kFirstRoundSamples; }
    /// Whether a pixel's error is above its stopping point (after any round):
    /// standard_error() > T (n / 16)^(3/4). Why the point grows with n: the samples that lower
    /// the image's squared error most for their cost go to the pixels that gain most per
    /// sample. A pixel's samples are stratified, so on an edge (where the error is) its mean's
    /// squared error falls about as s^2 / n^1.5 (s the samples' spread), not the s^2 / n of
    /// independent samples; a doubling round then gains about s^2 / n^1.5 for n samples, so
    /// the best next samples go to the largest s^2 / n^2.5, and a pixel should stop at
    /// s <= c n^1.25: a standard error sqrt(s^2 / n) <= c n^0.75. Measured at uniform 16 spp's
    /// error (docs/adaptive-sampling.md, Figures): exponents 0 (a fixed standard error), 0.5,
    /// 0.625, 0.75 and 1 gave whitted 0.72 (before corner weights), 0.333, 0.320, 0.317, 0.321 of uniform 16's rays,
    /// textured 0.83, 0.325, 0.317, 0.311, 0.308, soft shadows (independent area-light
    /// noise, for which 0.5 is the exponent) 0.128, 0.125, 0.125, 0.128, 0.140. Squared and
    /// multiplied out: 64 s2 n(n-1) > T^2 n^3 (n - 1) sqrt(n), one root and no division
    /// (it runs for every pixel of every round).
    bool above(const PixelTally& tally) const { return above(tally.scaled_variance(), tally.n); }
    /// above() of a pixel of `count` samples whose PixelTally::scaled_variance() is given.
    bool above(double scaled_variance, int count) const {
        if (count < 2) return true;
        const double n = count;
        return scaled_variance * kThresholdPower > threshold * threshold * n * n * n * (n - 1) * std::sqrt(n);
    }
    /// Whether a pixel with `tally` takes round r: it took every round before r, round r
    /// exists, and: round 0 always; round 1 when `spread_near` (its own or one of its eight
    /// neighbours' errors after round 0 is above(): a pixel whose first few samples all fell
    /// on one side of an edge sees the edge through a neighbour); later rounds when its own
    /// error is still above().
    bool takes_round(const PixelTally& tally, int r, bool spread_near) const {
        return takes_round(tally, r, adaptive_round(r, cap), spread_near);
    }
    /// The same with round r's run given (a loop over pixels works it out once).
    bool takes_round(const PixelTally& tally, int r, SampleRun run, bool spread_near) const {
        if (run.count == 0 || tally.n != run.first) return false;
        return r == 0 || (r == 1 ? spread_near : above(tally));
    }
};

/// Where a whole-image adaptive render spent its wall time (driver/adaptive_render.cpp), for
/// --profile: the corner round, the neighbour rule (each pixel's corners against T, then its
/// eight neighbours'), the later rounds, and the final pass (means, sample map, error). When
/// nothing stops the render between rounds (no image target, no clock), each tile looks at its
/// neighbours, runs its rounds and writes its pixels in one go: that is all `rounds`, the
/// neighbour rule is the flags alone and the final pass 0.
struct AdaptivePhases {
    double corners = 0, neighbour_rule = 0, rounds = 0, final_pass = 0;
};

/// An adaptive render's outcome, for the closing line and the profile.
struct AdaptiveSummary {
    double mean_spp = 0;        ///< samples taken per pixel, on average
    double estimated_rmse = 0;  ///< sqrt(mean of the pixels' image_error_squared())
    int rounds = 0;             ///< rounds run
    bool time_limited = false;  ///< --time-limit stopped the refinement
    int cap = 0;                ///< the most samples a pixel may take (--spp)
    double threshold = 0;       ///< T, each pixel's stopping point at 16 samples
    double target_error = 0;    ///< the image's target (--target-error; 0: none)
    /// Pixels that hold `cap` samples with their error still above their stopping point:
    /// the cap, not T, ended them.
    std::uint64_t above_at_cap = 0;
    AdaptivePhases seconds;     ///< wall time by phase

    /// Why the render ended short of what was asked, so that no front end reports a request
    /// as kept when it was not: NotCut when it was kept (the image's target reached, or
    /// without one every pixel under its stopping point); TimeLimit when --time-limit ran
    /// out first; Cap when pixels were still above their stopping point at the cap;
    /// Threshold when every pixel met T and the image's estimate is still above the target.
    enum class Cut { NotCut, TimeLimit, Cap, Threshold };
    Cut cut() const {
        const bool kept = target_error > 0 ? estimated_rmse <= target_error : above_at_cap == 0 && !time_limited;
        if (kept) return Cut::NotCut;
        if (time_limited) return Cut::TimeLimit;
        return above_at_cap > 0 ? Cut::Cap : Cut::Threshold;
    }
};

}  // namespace streamrt
