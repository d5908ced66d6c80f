#pragma once
// What a render did, for the summary line and the profile.
#include <atomic>
#include <cstdint>

namespace streamrt {

/// Diffuse: a degree-6 bounce off a surface's diffuse part (render/shading.h).
enum class RayKind : std::uint8_t { Primary, Reflected, Refracted, Diffuse };

struct RayCounts {
    std::uint64_t primary = 0, shadow = 0, reflected = 0, refracted = 0, diffuse = 0;
    std::uint64_t total() const { return primary + shadow + reflected + refracted + diffuse; }
    /// The counter of children of `kind` (reflected, refracted or diffuse).
    std::uint64_t& children(RayKind kind) {
        return kind == RayKind::Reflected ? reflected : kind == RayKind::Refracted ? refracted : diffuse;
    }
    RayCounts& operator+=(const RayCounts& o) {
        primary += o.primary;
        shadow += o.shadow;
        reflected += o.reflected;
        refracted += o.refracted;
        diffuse += o.diffuse;
        return *this;
    }
};

/// Shared between tiles: counts added once per tile, progress read by the display thread.
struct RenderProgress {
    std::atomic<std::uint64_t> primary{0}, shadow{0}, reflected{0}, refracted{0}, diffuse{0};
    std::atomic<int> tiles_done{0};
    int tiles_total = 0;
    std::atomic<bool>* cancel = nullptr;  ///< set from a signal handler to stop early

    void add(const RayCounts& c) {
        add_rays(c);
        ++tiles_done;
    }
    /// Rays of work on a tile already counted done (adaptive sampling's later rounds).
    void add_rays(const RayCounts& c) {
        primary += c.primary;
        shadow += c.shadow;
        reflected += c.reflected;
        refracted += c.refracted;
        diffuse += c.diffuse;
    }
    RayCounts counts() const {
        return {primary.load(), shadow.load(), reflected.load(), refracted.load(), diffuse.load()};
    }
    bool cancelled() const { return cancel && cancel->load(std::memory_order_relaxed); }
};

}  // namespace streamrt
