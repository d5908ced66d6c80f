#include "stream/profile.h"

#include <cstdio>

namespace streamrt {

const char* stage_name(Stage s) {
    switch (s) {
        case Stage::Generate: return "generate";
        case Stage::Intersect: return "intersect";
        case Stage::Shade: return "shade+spawn";
        case Stage::Occlusion: return "occlusion";
        case Stage::Accumulate: return "accumulate";
    }
    return "?";
}

std::string StreamProfile::text() const {
    std::string out;
    char line[256];
    std::snprintf(line, sizeof line, "stream profile: isa %s (%d float lanes), %d thread(s), wall %.4f s\n",
                  isa.c_str(), lanes, threads, wall_seconds);
    out += line;
    out += "pipeline built:";
    for (const auto& b : built) out += " " + b;
    out += "\n";
    double total_ns = 0;
    for (const auto& s : stages) total_ns += double(s.nanoseconds);
    std::snprintf(line, sizeof line, "%-12s %12s %12s %10s %7s %10s %8s\n", "stage", "rays in", "rays out", "cpu s",
                  "share", "Mrays/s", "lanes");
    out += line;
    for (int i = 0; i < kStageCount; ++i) {
        const StageFigures& s = stages[std::size_t(i)];
        if (s.rays_in == 0 && s.nanoseconds == 0) continue;
        const double sec = double(s.nanoseconds) * 1e-9;
        const double mrays = sec > 0 ? double(s.rays_in) / sec / 1e6 : 0;
        char lanes_txt[16] = "-";
        if (s.lanes_total) std::snprintf(lanes_txt, sizeof lanes_txt, "%.1f%%", 100.0 * double(s.lanes_used) / double(s.lanes_total));
        std::snprintf(line, sizeof line, "%-12s %12llu %12llu %10.4f %6.1f%% %10.2f %8s\n", stage_name(Stage(i)),
                      (unsigned long long)s.rays_in, (unsigned long long)s.rays_out, sec,
                      total_ns > 0 ? 100.0 * double(s.nanoseconds) / total_ns : 0.0, mrays, lanes_txt);
        out += line;
    }
    std::snprintf(line, sizeof line,
                  "rays: primary %llu, shadow %llu, reflected %llu, refracted %llu, diffuse %llu, total %llu (%.2f Mrays/s "
                  "wall)\n",
                  (unsigned long long)counts.primary, (unsigned long long)counts.shadow,
                  (unsigned long long)counts.reflected, (unsigned long long)counts.refracted,
                  (unsigned long long)counts.diffuse,
                  (unsigned long long)counts.total(), wall_seconds > 0 ? double(counts.total()) / wall_seconds / 1e6 : 0.0);
    out += line;
    out += "(stage times are thread CPU time, summed over threads; Mrays/s = rays in / cpu s)\n";
    bool any_generation = false;
    for (const auto& g : generations) any_generation = any_generation || g.rays > 0 || g.shadow_rays > 0;
    if (any_generation) {
        std::snprintf(line, sizeof line, "%-10s %10s  %-32s %11s %9s %12s %11s %9s\n", "generation", "rays",
                      "(primary/reflected/refracted/diffuse)", "intersect s", "Mrays/s", "shadow rays", "occlusion s", "Mrays/s");
        out += line;
        for (std::size_t d = 0; d < generations.size(); ++d) {
            const GenerationFigures& g = generations[d];
            if (g.rays == 0 && g.shadow_rays == 0) continue;
            const double isec = double(g.intersect_ns) * 1e-9, osec = double(g.occlusion_ns) * 1e-9;
            char kinds[80];
            std::snprintf(kinds, sizeof kinds, "(%llu/%llu/%llu/%llu)", (unsigned long long)g.primary,
                          (unsigned long long)g.reflected, (unsigned long long)g.refracted,
                          (unsigned long long)g.diffuse);
            std::snprintf(line, sizeof line, "%-10zu %10llu  %-32s %11.4f %9.2f %12llu %11.4f %9.2f\n", d,
                          (unsigned long long)g.rays, kinds, isec, isec > 0 ? double(g.rays) / isec / 1e6 : 0.0,
                          (unsigned long long)g.shadow_rays, osec,
                          osec > 0 ? double(g.shadow_rays) / osec / 1e6 : 0.0);
            out += line;
        }
        out += "(the intersect and occlusion rows by ray generation, 0 = camera rays; shadow rays by the "
               "generation that cast them)\n";
    }
    if (adaptive) {
        const AdaptivePhases& p = adaptive->seconds;
        std::snprintf(line, sizeof line,
                      "adaptive: %.2f samples per pixel (at most %d), %d round(s), estimated error %.3g; wall s: "
                      "corners %.4f, neighbour rule %.4f, rounds %.4f, final pass %.4f\n",
                      adaptive->mean_spp, adaptive->cap, adaptive->rounds, adaptive->estimated_rmse, p.corners,
                      p.neighbour_rule, p.rounds, p.final_pass);
        out += line;
    }
    return out;
}

std::string StreamProfile::json() const {
    std::string out = "{\n";
    char buf[512];
    std::snprintf(buf, sizeof buf, "  \"isa\": \"%s\",\n  \"lanes\": %d,\n  \"threads\": %d,\n  \"wall_seconds\": %.6f,\n",
                  isa.c_str(), lanes, threads, wall_seconds);
    out += buf;
    out += "  \"built\": [";
    for (std::size_t i = 0; i < built.size(); ++i) out += (i ? ", \"" : "\"") + built[i] + "\"";
    out += "],\n  \"stages\": [\n";
    bool first = true;
    for (int i = 0; i < kStageCount; ++i) {
        const StageFigures& s = stages[std::size_t(i)];
        if (s.rays_in == 0 && s.nanoseconds == 0) continue;
        const double sec = double(s.nanoseconds) * 1e-9;
        std::snprintf(buf, sizeof buf,
                      "%s    {\"stage\": \"%s\", \"rays_in\": %llu, \"rays_out\": %llu, \"cpu_seconds\": %.6f, "
                      "\"mrays_per_s\": %.3f, \"lane_utilisation\": %.4f}",
                      first ? "" : ",\n", stage_name(Stage(i)), (unsigned long long)s.rays_in,
                      (unsigned long long)s.rays_out, sec, sec > 0 ? double(s.rays_in) / sec / 1e6 : 0.0,
                      s.lanes_total ? double(s.lanes_used) / double(s.lanes_total) : 1.0);
        out += buf;
        first = false;
    }
    out += "\n  ],\n  \"generations\": [\n";
    first = true;
    for (std::size_t d = 0; d < generations.size(); ++d) {
        const GenerationFigures& g = generations[d];
        if (g.rays == 0 && g.shadow_rays == 0) continue;
        const double isec = double(g.intersect_ns) * 1e-9, osec = double(g.occlusion_ns) * 1e-9;
        std::snprintf(buf, sizeof buf,
                      "%s    {\"generation\": %zu, \"rays\": %llu, \"primary\": %llu, \"reflected\": %llu, "
                      "\"refracted\": %llu, \"diffuse\": %llu, \"intersect_cpu_seconds\": %.6f, \"intersect_mrays_per_s\": %.3f, "
                      "\"shadow_rays\": %llu, \"occlusion_cpu_seconds\": %.6f, \"occlusion_mrays_per_s\": %.3f}",
                      first ? "" : ",\n", d, (unsigned long long)g.rays, (unsigned long long)g.primary,
                      (unsigned long long)g.reflected, (unsigned long long)g.refracted, (unsigned long long)g.diffuse,
                      isec,
                      isec > 0 ? double(g.rays) / isec / 1e6 : 0.0, (unsigned long long)g.shadow_rays, osec,
                      osec > 0 ? double(g.shadow_rays) / osec / 1e6 : 0.0);
        out += buf;
        first = false;
    }
    std::snprintf(buf, sizeof buf,
                  "\n  ],\n  \"rays\": {\"primary\": %llu, \"shadow\": %llu, \"reflected\": %llu, \"refracted\": %llu, "
                  "\"diffuse\": %llu}",
                  (unsigned long long)counts.primary, (unsigned long long)counts.shadow,
                  (unsigned long long)counts.reflected, (unsigned long long)counts.refracted,
                  (unsigned long long)counts.diffuse);
    out += buf;
    if (adaptive) {
        const AdaptivePhases& p = adaptive->seconds;
        std::snprintf(buf, sizeof buf,
                      ",\n  \"adaptive\": {\"mean_spp\": %.6f, \"cap\": %d, \"rounds\": %d, \"estimated_rmse\": %.6g, "
                      "\"time_limited\": %s, \"wall_seconds\": {\"corners\": %.6f, \"neighbour_rule\": %.6f, "
                      "\"rounds\": %.6f, \"final_pass\": %.6f}}",
                      adaptive->mean_spp, adaptive->cap, adaptive->rounds, adaptive->estimated_rmse,
                      adaptive->time_limited ? "true" : "false", p.corners, p.neighbour_rule, p.rounds, p.final_pass);
        out += buf;
    }
    out += "\n}\n";
    return out;
}

}  // namespace streamrt
