"""streamrt: a SIMD ray-stream ray tracer and its recursive baseline (docs/python.md).

The calls live in the extension streamrt._native (engine/python/module.cpp); this package
holds it, its type stubs (__init__.pyi) and, installed by pip, the modules it loads on first
use (libstreamrt_exr.so, libstreamrt_mpi.so). `python -m streamrt` runs the command line."""
from ._native import Result, Scene, SceneError, compare, render, save

__all__ = ["Result", "Scene", "SceneError", "compare", "render", "save"]

# Named as the package, not its extension, in help(), reprs and tracebacks.
for _name in __all__:
    globals()[_name].__module__ = __name__
del _name
