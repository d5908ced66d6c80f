// The `streamrt` Python module (docs/python.md): render, profile and compare from Python,
// pictures as NumPy arrays. It calls the engine's one entry point (driver/render.h) on the
// render job the command line builds, so a picture from Python is the CLI's picture, bit for
// bit. Rendering runs on a worker thread with the GIL released; the calling thread waits,
// looking at Python's signals (Ctrl-C becomes KeyboardInterrupt, the render is cancelled
// within a chunk) and calling the progress callback. Built as streamrt._native, the
// extension of the streamrt package (python/streamrt/): `python -m streamrt` runs the
// command line itself (cli/command.cpp) through run_command.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "cli/cli.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "driver/limits.h"
#include "driver/render.h"
#include "driver/render_job.h"
#include "image/image_compare.h"
#include "image/image_io.h"
#include "parallel/parallelism.h"
#include "mesh/mesh.h"
#include "scene/parser.h"

namespace py = pybind11;
using namespace streamrt;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// A scene built from Python: statements in the .cfg format (so every value goes through the
/// scene reader's checks and messages) and meshes from NumPy arrays, held in memory and named
/// by their statements as file=memory:K.
struct PyScene {
    std::vector<std::string> lines;
    std::vector<std::shared_ptr<const Mesh>> meshes;
    std::string text() const {
        std::string t;
        for (const std::string& l : lines) (t += l) += '\n';
        return t;
    }
};

/// `with scene.csg(op, **keys):` — the block's `csg` line on entering, its `end` on leaving
/// (also when the body raised, so the scene's text stays balanced).
struct PyCsgBlock {
    PyScene* scene;
    std::string line;
};

/// A keyword value in the scene format: tuples and lists as "a,b,c", booleans true/false.
std::string format_value(const py::handle& v) {
    if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
    if (py::isinstance<py::tuple>(v) || py::isinstance<py::list>(v) || py::isinstance<py::array>(v)) {
        std::string s;
        for (const py::handle& x : v) s += (s.empty() ? "" : ",") + format_value(x);
        return s;
    }
    if (py::isinstance<py::float_>(v)) return py::repr(v).cast<std::string>();
    return py::str(v).cast<std::string>();
}

std::string statement(const std::string& word, const py::kwargs& kw) {
    std::string s = word;
    // Appended piece by piece: GCC 12 reads `" " + std::string&&` as a possible overlapping
    // copy (a false -Wrestrict).
    for (const auto& [k, v] : kw) s.append(" ").append(py::str(k).cast<std::string>()).append("=").append(format_value(v));
    return s;
}


/// A scene given as a path to a .cfg file, or as the text of one (anything that is not an
/// existing file): the text's messages name it "<string>".
Scene read_scene(const PyScene& scene, int threads) {
    ReadOptions options;
    options.jobs = threads;
    options.memory_meshes = &scene.meshes;
    return parse_scene(scene.text(), "<scene>", options);
}
Scene read_scene(const std::string& scene, int threads) {
    std::error_code ec;
    if (scene.find('\n') == std::string::npos && std::filesystem::is_regular_file(scene, ec))
        return load_scene(scene, threads);
    ReadOptions options;
    options.jobs = threads;
    return parse_scene(scene, "<string>", options);
}

/// The picture as a float32 NumPy array, height x width x 3, top row first, owning the
/// framebuffer's memory (no copy).
py::array_t<float> to_array(Framebuffer&& fb) {
    auto* owned = new Framebuffer(std::move(fb));
    py::capsule free_it(owned, [](void* p) { delete static_cast<Framebuffer*>(p); });
    const py::ssize_t h = owned->height, w = owned->width;
    return py::array_t<float>({h, w, py::ssize_t(3)},
                              {py::ssize_t(sizeof(float)) * w * 3, py::ssize_t(sizeof(float)) * 3,
                               py::ssize_t(sizeof(float))},
                              owned->rgb.data(), free_it);
}

/// One finished render, as Python sees it.
struct Result {
    py::array_t<float> image;
    py::dict seconds, rays;
    py::object profile = py::none();
    std::string engine;
    py::object adaptive = py::none();  ///< adaptive sampling: its summary and sample map
};

/// Renders `job` on a worker thread while this (the Python) thread waits with the GIL
/// released, waking every 50 ms to run Python's signal handlers and the progress callback.
/// A pending KeyboardInterrupt (or an exception from the callback) cancels the render.
RenderResult render_watched(const RenderJob& job, EngineKind engine, const py::object& progress) {
    std::atomic<bool> cancel{false};
    RenderProgress watch;
    watch.cancel = &cancel;
    RenderResult result;
    std::exception_ptr failure;
    std::atomic<bool> done{false};
    std::thread worker([&] {
        try {
            Parallelism par(job.threads);
            auto prepared = prepare_job(job, engine, job.settings.frame);
            watch.tiles_total = tile_count(prepared->width, prepared->height);
            result = render_prepared(*prepared, par, &watch);
        } catch (...) {
            failure = std::current_exception();
        }
        done = true;
    });
    std::optional<py::error_already_set> interrupted;
    int reported = -1;
    while (!done) {
        {
            py::gil_scoped_release release;
            for (int i = 0; i < 10 && !done; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        if (interrupted) continue;  // cancelled: wait for the worker to stop
        if (PyErr_CheckSignals() != 0) {
            interrupted.emplace();  // takes the pending exception (KeyboardInterrupt)
            cancel = true;
            continue;
        }
        const int tiles = watch.tiles_done.load();
        if (!progress.is_none() && tiles != reported) {
            reported = tiles;
            try {
                progress(tiles, watch.tiles_total);
            } catch (py::error_already_set& e) {
                interrupted.emplace(std::move(e));
                cancel = true;
            }
        }
    }
    {
        py::gil_scoped_release release;
        worker.join();
    }
    if (interrupted) throw std::move(*interrupted);
    if (failure) std::rethrow_exception(failure);
    // The closing call reports the tiles the render counted, not the total taken for granted:
    // a render that lost count of its tiles says so.
    if (!progress.is_none()) progress(watch.tiles_done.load(), watch.tiles_total);
    return result;
}

Result make_result(RenderResult&& r, const RenderJob& job, EngineKind engine, double read_seconds) {
    Result out;
    out.engine = engine_name(engine);
    out.seconds["read"] = read_seconds;
    out.seconds["setup"] = r.setup_seconds;
    out.seconds["render"] = r.seconds;
    out.rays["primary"] = r.counts.primary;
    out.rays["shadow"] = r.counts.shadow;
    out.rays["reflected"] = r.counts.reflected;
    out.rays["refracted"] = r.counts.refracted;
    out.rays["diffuse"] = r.counts.diffuse;
    out.rays["total"] = r.counts.total();
    if (job.profile && engine == EngineKind::Stream) {
        job.profile->adaptive = r.adaptive;  // as the command line's profile
        out.profile = py::module_::import("json").attr("loads")(job.profile->json());
    }
    if (r.adaptive) {
        py::dict a;
        a["mean_spp"] = r.adaptive->mean_spp;
        a["estimated_rmse"] = r.adaptive->estimated_rmse;
        a["rounds"] = r.adaptive->rounds;
        a["time_limited"] = r.adaptive->time_limited;
        a["cap"] = r.adaptive->cap;
        a["cap_from"] = job.adaptive_cap_from == AdaptiveCapFrom::Given   ? "spp"
                        : job.adaptive_cap_from == AdaptiveCapFrom::Scene ? "scene"
                                                                          : "default";
        a["above_at_cap"] = r.adaptive->above_at_cap;
        // What kept the request (target_error, or adaptive's threshold in every pixel) from
        // being met, as the command line's closing line says it: None when it was met.
        using Cut = AdaptiveSummary::Cut;
        const Cut cut = r.adaptive->cut();
        a["cut_short_by"] = cut == Cut::NotCut      ? py::object(py::none())
                            : cut == Cut::TimeLimit ? py::object(py::str("time_limit"))
                            : cut == Cut::Cap       ? py::object(py::str("cap"))
                                                    : py::object(py::str("threshold"));
        py::dict phases;  // wall seconds, as --profile reports them
        phases["corners"] = r.adaptive->seconds.corners;
        phases["neighbour_rule"] = r.adaptive->seconds.neighbour_rule;
        phases["rounds"] = r.adaptive->seconds.rounds;
        phases["final_pass"] = r.adaptive->seconds.final_pass;
        a["seconds"] = phases;
        a["sample_map"] = to_array(std::move(r.sample_map));
        out.adaptive = a;
    }
    out.image = to_array(std::move(r.image));
    return out;
}

/// The keyword arguments every call takes, as the command line's overrides.
/// memory_limit=: the process's memory budget for one call (core/memory_budget.h), as the
/// command line's --memory-limit; the one before is back when the call returns.
struct ScopedMemoryLimit {
    double before = MemoryBudget::limit();
    ~ScopedMemoryLimit() { MemoryBudget::set_limit(before); }
    void set(const py::handle& value) {
        const double bytes = py::isinstance<py::str>(value) ? parse_memory_size(value.cast<std::string>(), "memory_limit")
                                                            : value.cast<double>();
        if (!(bytes >= 1)) throw UsageError("memory_limit: expected a positive size (bytes, or text such as '4G')");
        MemoryBudget::set_limit(bytes);
    }
};

RenderOverrides overrides_of(const py::kwargs& kw, bool& profile, py::object& progress, ScopedMemoryLimit& memory) {
    RenderOverrides o;
    for (const auto& [key, value] : kw) {
        const std::string k = py::str(key);
        if (value.is_none()) continue;
        if (k == "profile") profile = value.cast<bool>();
        else if (k == "progress") progress = py::reinterpret_borrow<py::object>(value);
        else if (k == "memory_limit") memory.set(value);
        else if (!set_override(o, k, py::str(value).cast<std::string>()))
            throw py::type_error("unexpected keyword argument '" + k + "' (expected one of: " + override_names() +
                                 ", profile, progress, memory_limit)");
    }
    return o;
}

/// The scene a call names: a Scene built in Python, a .cfg path, or .cfg text; immutable
/// once read (the job renders it with its own settings).
std::shared_ptr<const Scene> read_any(const py::object& scene, int threads) {
    if (py::isinstance<PyScene>(scene)) {
        const PyScene& s = scene.cast<const PyScene&>();
        py::gil_scoped_release release;
        return std::make_shared<const Scene>(read_scene(s, threads));
    }
    const std::string text = scene.cast<std::string>();
    // One line ending in .cfg is a path, not scene text: a mistyped name was read as a scene
    // and refused as "unknown statement 'scenes/whited.cfg'", hiding what was wrong.
    std::error_code ec;
    if (text.find('\n') == std::string::npos && text.ends_with(".cfg") && !std::filesystem::exists(text, ec)) {
        const py::object error = py::module_::import("builtins").attr("FileNotFoundError")(
            ENOENT, "no such scene file (one line ending in .cfg is read as a path)", text);
        PyErr_SetObject(PyExc_FileNotFoundError, error.ptr());
        throw py::error_already_set();
    }
    py::gil_scoped_release release;
    return std::make_shared<const Scene>(read_scene(text, threads));
}

Result render(const py::object& scene, const py::kwargs& kw) {
    bool profile = false;
    py::object progress = py::none();
    ScopedMemoryLimit memory;
    const RenderOverrides o = overrides_of(kw, profile, progress, memory);
    const auto start = Clock::now();
    std::shared_ptr<const Scene> sc = read_any(scene, o.threads.value_or(0));
    const double read_seconds = since(start);
    RenderJob job = build_render_job(std::move(sc), o, profile);
    // Refused before anything big is allocated, as on the command line.
    check_render_memory(*job.scene, job.render_settings, true, job.threads > 0 ? job.threads : default_jobs());
    RenderResult r = render_watched(job, job.engine, progress);
    return make_result(std::move(r), job, job.engine, read_seconds);
}

py::dict compare(const py::object& scene, const py::kwargs& kw) {
    bool profile = false;
    py::object progress = py::none();
    ScopedMemoryLimit memory;
    const RenderOverrides o = overrides_of(kw, profile, progress, memory);
    const auto start = Clock::now();
    std::shared_ptr<const Scene> sc = read_any(scene, o.threads.value_or(0));
    const double read_seconds = since(start);
    RenderJob job = build_render_job(std::move(sc), o, profile);
    // Refused before anything big is allocated, as on the command line.
    check_render_memory(*job.scene, job.render_settings, true, job.threads > 0 ? job.threads : default_jobs());
    RenderResult stream = render_watched(job, EngineKind::Stream, progress);
    RenderResult recursive = render_watched(job, EngineKind::Recursive, progress);
    const ImageDifference d = compare_images(stream.image, recursive.image);
    py::dict out;
    out["speedup"] = recursive.seconds / std::max(stream.seconds, 1e-9);
    out["rmse"] = d.rmse;
    out["psnr"] = d.psnr;
    out["max_abs"] = d.max_abs;
    out["share_over"] = d.share_over;
    out["stream"] = make_result(std::move(stream), job, EngineKind::Stream, read_seconds);
    out["recursive"] = make_result(std::move(recursive), job, EngineKind::Recursive, read_seconds);
    return out;
}

void save(py::array_t<float, py::array::c_style | py::array::forcecast> image, const std::string& path,
          const std::string& colorspace, const std::string& tonemap, double exposure) {
    if (image.ndim() != 3 || image.shape(2) != 3)
        throw py::value_error("expected an image of shape (height, width, 3)");
    Framebuffer fb = Framebuffer::uninitialized(int(image.shape(1)), int(image.shape(0)));
    std::copy(image.data(), image.data() + fb.rgb.size(), fb.rgb.begin());
    Display d;
    const auto cs = value_named(kColorSpaceNames, colorspace);
    if (!cs) throw py::value_error("colorspace: expected " + names_list(kColorSpaceNames));
    const auto tm = value_named(kTonemapNames, tonemap);
    if (!tm) throw py::value_error("tonemap: expected " + names_list(kTonemapNames));
    d.colorspace = *cs, d.tonemap = *tm;
    d.exposure = float(exposure);
    py::gil_scoped_release release;
    write_image(path, fb, d);
}

/// python -m streamrt ARGS: the command line in this process, its exit status returned. The
/// command sets its own SIGINT and SIGTERM handlers (Ctrl-C stops the render, status 130);
/// Python's are put back afterwards.
int run_command(const std::vector<std::string>& args) {
    std::vector<std::string> words{"streamrt"};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    struct sigaction python_int {}, python_term {};
    sigaction(SIGINT, nullptr, &python_int);
    sigaction(SIGTERM, nullptr, &python_term);
    int status;
    {
        py::gil_scoped_release release;
        status = cli::run_command(int(words.size()), argv.data());
        std::fflush(stdout);  // before anything Python prints next
    }
    sigaction(SIGINT, &python_int, nullptr);
    sigaction(SIGTERM, &python_term, nullptr);
    return status;
}

}  // namespace

PYBIND11_MODULE(_native, m) {
    m.doc() = "streamrt: a SIMD ray-stream ray tracer and its recursive baseline (docs/python.md).";

    static py::exception<SceneError> scene_error(m, "SceneError", PyExc_ValueError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const SceneError& e) {
            py::object err = py::reinterpret_borrow<py::object>(scene_error.ptr())(py::str(e.what()));
            err.attr("file") = e.where().file;
            err.attr("line") = e.where().line;
            err.attr("column") = e.where().column;
            err.attr("message") = e.message();
            PyErr_SetObject(scene_error.ptr(), err.ptr());
        } catch (const UsageError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        } catch (const MemoryShortage& e) {
            PyErr_SetString(PyExc_MemoryError, e.what());
        } catch (const RenderError& e) {
            PyErr_SetString(PyExc_RuntimeError, e.what());
        }
    });

    py::class_<Result>(m, "Result", "One render: the picture, its times, its rays and (profile=True) the stream profile.")
        .def_readonly("image", &Result::image, "float32 array, height x width x 3, linear, top row first")
        .def_readonly("seconds", &Result::seconds, "{'read', 'setup', 'render'}: seconds")
        .def_readonly("rays", &Result::rays, "{'primary', 'shadow', 'reflected', 'refracted', 'diffuse', 'total'}")
        .def_readonly("profile", &Result::profile, "the content of --profile=json as a dict, or None")
        .def_readonly("engine", &Result::engine, "'stream' or 'recursive'")
        .def_readonly("adaptive", &Result::adaptive,
                      "adaptive sampling: {'mean_spp', 'estimated_rmse', 'rounds', 'time_limited', 'cap', 'cap_from', "
                      "'above_at_cap', 'cut_short_by', 'seconds', 'sample_map'} "
                      "(sample_map: height x width x 3, samples taken and estimated error per pixel), or None")
        .def("__repr__", [](const Result& r) {
            return "<streamrt.Result " + r.engine + " " + std::to_string(r.image.shape(1)) + "x" +
                   std::to_string(r.image.shape(0)) + ", " + py::str(r.seconds["render"]).cast<std::string>() + " s>";
        });

    py::class_<PyScene>(m, "Scene",
                        "A scene built from Python: statements of the .cfg format (docs/scene-format.md) and\n"
                        "meshes from NumPy arrays. Render it with streamrt.render(scene, ...).")
        .def(py::init<>())
        .def("add", [](PyScene& s, const std::string& text) {
                for (std::size_t b = 0, e; b <= text.size(); b = e + 1) {
                    e = std::min(text.find('\n', b), text.size());
                    s.lines.push_back(text.substr(b, e - b));
                }
            }, py::arg("text"), "Appends statements (one or more lines of .cfg text).")
        .def("statement", [](PyScene& s, const std::string& word, const py::kwargs& kw) {
                s.lines.push_back(statement(word, kw));
            }, py::arg("word"), "Appends one statement from keywords: statement('sphere', color=(1, 0, 0), translate=(0, 1, 0)).")
        .def("mesh", [](PyScene& s, py::array_t<float, py::array::c_style | py::array::forcecast> vertices,
                        py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast> triangles,
                        const py::object& colors_arg, const py::kwargs& kw) {
                if (vertices.ndim() != 2 || vertices.shape(1) != 3)
                    throw py::value_error("vertices: expected an array of shape (n, 3)");
                if (triangles.ndim() != 2 || triangles.shape(1) != 3)
                    throw py::value_error("triangles: expected an array of shape (m, 3) of vertex numbers");
                const std::vector<float> positions(vertices.data(), vertices.data() + vertices.size());
                const std::vector<std::uint32_t> tris(triangles.data(), triangles.data() + triangles.size());
                for (const std::uint32_t v : tris)
                    if (v >= std::uint32_t(vertices.shape(0)))
                        throw py::value_error("triangles: vertex number " + std::to_string(v) + " out of range");
                std::vector<float> colors;
                if (!colors_arg.is_none()) {
                    const auto c = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(colors_arg);
                    if (!c || c.ndim() != 2 || c.shape(1) != 3 || c.shape(0) != vertices.shape(0))
                        throw py::value_error("colors: expected an array of shape (n, 3), one linear RGB colour per vertex");
                    colors.assign(c.data(), c.data() + c.size());
                    for (const float x : colors)
                        if (!std::isfinite(x) || x < 0.f) throw py::value_error("colors: components must be finite and >= 0");
                }
                const std::string name = "memory:" + std::to_string(s.meshes.size());
                std::shared_ptr<const Mesh> mesh;
                {
                    py::gil_scoped_release release;
                    mesh = Mesh::build(name, positions, tris, {}, {}, {}, colors);
                }
                if (mesh->triangle_count() == 0) throw py::value_error("the mesh has no non-degenerate triangle");
                s.meshes.push_back(std::move(mesh));
                s.lines.push_back(statement("mesh file=" + name, kw));
            }, py::arg("vertices"), py::arg("triangles"), py::kw_only(), py::arg("colors") = py::none(),
            "Appends a mesh object from arrays (vertices (n, 3), triangles (m, 3), counter-clockwise seen\n"
            "from outside) with the mesh statement's other keys: mesh(v, t, smooth=True, color=(1, 0, 0)).\n"
            "colors: (n, 3) linear RGB per vertex, shown with vertex_colors=True.")
        .def("csg", [](PyScene& s, const std::string& op, const py::kwargs& kw) {
                return PyCsgBlock{&s, statement("csg " + op, kw)};
            }, py::arg("op"), py::keep_alive<0, 1>(),
            "A csg block (docs/scene-format.md, \"CSG\") as a context: the statements added in its\n"
            "body are its children. with scene.csg('difference', material='steel', rotate_x=90):\n"
            "    scene.statement('cylinder', scale=(1, 2, 1)); scene.statement('cylinder', scale=(0.8, 2.1, 0.8))")
        .def_property_readonly("text", &PyScene::text, "The statements as .cfg text (meshes as file=memory:K).");

    py::class_<PyCsgBlock>(m, "CsgBlock", "A csg block being written: use it in a with statement (Scene.csg).")
        .def("__enter__", [](PyCsgBlock& b) {
                b.scene->lines.push_back(b.line);
                return b.scene;
            }, py::return_value_policy::reference)
        .def("__exit__", [](PyCsgBlock& b, const py::args&) {
                b.scene->lines.push_back("end");
                return false;
            });

    m.def("render", &render, py::arg("scene"),
          "render(scene, **overrides) -> Result\n\n"
          "scene: a path to a .cfg file or the text of one. overrides: the command line's\n"
          "(width, height, spp, depth, degree, sampler, cutoff, light_samples, engine, isa, accel,\n"
          "threads, frame), profile=True for the stream profile, progress=callable(done, total),\n"
          "memory_limit=bytes or '4G' (the command line's --memory-limit; MemoryError past it).");
    m.def("compare", &compare, py::arg("scene"),
          "compare(scene, **overrides) -> dict: both engines' Results ('stream', 'recursive') and\n"
          "their difference ('speedup', 'rmse', 'psnr', 'max_abs', 'share_over').");
    m.def("save", &save, py::arg("image"), py::arg("path"), py::arg("colorspace") = "srgb",
          py::arg("tonemap") = "clamp", py::arg("exposure") = 1.0,
          "save(image, path, colorspace='srgb', tonemap='clamp', exposure=1.0): writes a linear\n"
          "height x width x 3 image in the format of the path's extension (.png, .ppm, .pfm, .exr, .hdr).");
    m.def("run_command", &run_command, py::arg("args"),
          "run_command(args) -> int: the streamrt command line with these arguments (python -m streamrt).");
}
