#pragma once
// A kernel job's append view of a whole RayStream (tests of the generate kernels).
#include "kernels/ray_stream.h"
#include "kernels/shade_job.h"

namespace streamrt::test {

inline RayAppend append_view(RayStream& rays) {
    return {rays.ox.data(), rays.oy.data(), rays.oz.data(), rays.dx.data(), rays.dy.data(), rays.dz.data(),
            rays.t_max.data(), rays.wr.data(), rays.wg.data(), rays.wb.data(), rays.cone.data(),
            rays.pixel.data(), rays.kind.data(), &rays.count};
}

}  // namespace streamrt::test
