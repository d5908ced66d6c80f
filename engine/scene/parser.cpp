// The .cfg scene reader (docs/scene-format.md). One statement per line, `#` comments,
// `key=value` arguments; every mistake becomes a SceneError at the exact line and column of
// the offending token (the key, the value or the statement word).
//
// Speed (docs/architecture.md, "Scene reading"): the file is mapped, lines are cut with
// memchr and lexed into views kept in scratch vectors reused from line to line; a large file
// is cut into chunks at line ends, the rare non-shape statements run first in file order and
// the shapes of all chunks are parsed in parallel into their final slots of scene.objects.
#include "scene/parser.h"

#include "core/memory_advice.h"
#include "parallel/parallelism.h"
#include <algorithm>
#include <climits>
#include <cmath>
#include <string>
#include <vector>

#include "scene/parser_state.h"

namespace streamrt {
namespace scene_reader {

bool Parser::read_chunked(std::string_view text, const std::string& display, bool mapped) {
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 BOM
    std::vector<Chunk> chunks;
    const std::size_t step = std::max<std::size_t>(1, options_.chunk_bytes);
    for (std::size_t b = 0; b < text.size();) {
        std::size_t e = std::min(text.size(), b + step);
        if (e < text.size()) {
            const auto nl = text.find('\n', e - 1);
            const std::size_t probe = e - 1;
            e = nl == std::string_view::npos ? text.size() : nl + 1;
            // One fault may map a whole large folio of the page cache (up to 2 MiB here):
            // without this, the boundary probes alone left ~90% of a 100 MB file mapped.
            if (mapped) {
                constexpr std::size_t kFolio = std::size_t(2) << 20;
                advise_inside(text.data() + (probe > kFolio ? probe - kFolio : 0),
                              text.data() + std::min(text.size(), e + kFolio), MADV_DONTNEED);
            }
        }
        chunks.emplace_back();
        chunks.back().begin = b;
        chunks.back().end = e;
        b = e;
    }
    Parallelism par(options_.jobs);
    par.for_each_index(chunks.size(), 1, [&](std::size_t i) {
        survey(text, chunks[i]);
        if (mapped) advise_inside(text.data() + chunks[i].begin, text.data() + chunks[i].end, MADV_DONTNEED);
    });
    std::size_t objects = 0;
    int line = 1;
    bool sequential_only = false;
    for (Chunk& c : chunks) {
        sequential_only = sequential_only || c.sequential_only;
        c.first_line = line;
        c.first_object = objects;
        line += c.lines;
        objects += c.shapes;
    }
    if (sequential_only) {
        scene.objects.reserve(objects);  // this file's shapes at least: fewer regrowths
        return false;
    }
    chunked_ = true;
    ++files_;

    // The other statements, in file order; they stop at their first error. Their name=
    // (lights, camera) is recorded with the shapes' below, in file order.
    deferred_names_.clear();
    defer_names_ = true;
    std::exception_ptr other_error;
    int other_error_line = INT_MAX;
    for (const Chunk& c : chunks) {
        for (const auto& [offset, in_chunk] : c.others) {
            const int at = c.first_line + in_chunk;
            try {
                statement(line_at(text, offset), display, at, 0, scratch_);
            } catch (...) {
                other_error = std::current_exception();
                other_error_line = at;
                break;
            }
        }
        if (other_error) break;
    }
    defer_names_ = false;

    const std::uint32_t file = file_index(display);
    scene.objects.reserve(objects);
    Object* const slots = scene.objects.data();
    advise_inside(slots, slots + objects, MADV_HUGEPAGE, std::uintptr_t(2) << 20);
    par.for_each_index(chunks.size(), 1, [&](std::size_t i) {
        advise_inside(slots + chunks[i].first_object, slots + chunks[i].first_object + chunks[i].shapes,
                      MADV_POPULATE_WRITE);
    });
    scene.objects.resize(objects);
    scene.object_locs.resize(objects);
    // Every chunk is read even after an error: which error comes first is then decided
    // below in file order, never by which thread got there first.
    par.for_each_index(chunks.size(), 1, [&](std::size_t i) {
        read_shapes(text, display, file, chunks[i]);
        if (mapped) advise_inside(text.data() + chunks[i].begin, text.data() + chunks[i].end, MADV_DONTNEED);
    });
    // name= of every statement in file order, up to the first error (a bad or repeated name
    // before it is the first error, as in a one-pass read).
    int first_error_line = other_error_line;
    for (const Chunk& c : chunks)
        if (c.error) first_error_line = std::min(first_error_line, c.error_line);
    for (const Chunk& c : chunks)
        for (const Chunk::Name& n : c.names)
            deferred_names_.push_back({display, n.line, Arg{"name", n.column, n.text, n.column}, Named::Object,
                                       std::uint32_t(n.slot)});
    std::stable_sort(deferred_names_.begin(), deferred_names_.end(),
                     [](const DeferredName& a, const DeferredName& b) { return a.line < b.line; });
    for (const DeferredName& n : deferred_names_)
        if (n.line < first_error_line) name_thing(n.file, n.line, n.arg, n.what, n.index);
    for (const Chunk& c : chunks)
        if (c.error && c.error_line < other_error_line) std::rethrow_exception(c.error);
    if (other_error) std::rethrow_exception(other_error);
    deferred_names_.clear();
    // The chunks' materials into the scene's list in chunk order, then each object's
    // chunk-local index replaced by the scene's (skipped where they coincide).
    std::vector<std::vector<std::uint32_t>> remap(chunks.size());
    for (std::size_t i = 0; i < chunks.size(); ++i)
        for (const Material& m : chunks[i].materials.local()) remap[i].push_back(scene.intern_material(m));
    par.for_each_index(chunks.size(), 1, [&](std::size_t i) {
        const std::vector<std::uint32_t>& to = remap[i];
        bool identity = true;
        for (std::uint32_t k = 0; k < to.size(); ++k) identity = identity && to[k] == k;
        if (identity) return;
        for (std::size_t k = chunks[i].first_object; k < chunks[i].first_object + chunks[i].shapes; ++k)
            scene.objects[k].material = to[scene.objects[k].material];
    });
    return true;
}

std::string_view Parser::line_at(std::string_view text, std::size_t offset) {
    const auto nl = text.find('\n', offset);
    return text.substr(offset, (nl == std::string_view::npos ? text.size() : nl) - offset);
}

void Parser::survey(std::string_view text, Chunk& c) {
    for (std::size_t pos = c.begin; pos < c.end;) {
        const std::string_view line = line_at(text, pos);
        const std::string_view w = first_word(line);
        if (is_plain_shape(w)) ++c.shapes;
        else if (w == "include" || w == "mesh" || w == "key" || w == "csg") c.sequential_only = true;
        else if (!w.empty()) c.others.emplace_back(pos, c.lines);
        pos += line.size() + 1;
        ++c.lines;
    }
}

void Parser::read_shapes(std::string_view text, const std::string& display, std::uint32_t file, Chunk& c) {
    Scratch scratch;
    std::size_t slot = c.first_object;
    int line_no = c.first_line;
    try {
        for (std::size_t pos = c.begin; pos < c.end; ++line_no) {
            const std::string_view line = line_at(text, pos);
            pos += line.size() + 1;
            tokenize(line, scratch.toks);
            if (scratch.toks.empty()) continue;
            const auto kind = shape_from_word(scratch.toks[0].text);
            if (!kind) continue;  // already read, in file order
            Statement st(display, line_no, scratch.toks[0], scratch.args);
            if (const auto name = shape(st, scratch.toks, *kind, file, c.materials, scene.objects[slot],
                                        scene.object_locs[slot]))
                c.names.push_back({name->value, line_no, name->value_col, slot});
            ++slot;
        }
    } catch (...) {
        c.error = std::current_exception();
        c.error_line = line_no;
    }
}

void Parser::statement(std::string_view line, const std::string& file, int line_no, int depth, Scratch& scratch) {
    tokenize(line, scratch.toks);
    const std::vector<Token>& toks = scratch.toks;
    if (toks.empty()) return;
    Statement st(file, line_no, toks[0], scratch.args);
    const auto w = toks[0].text;
    const bool in_csg_block = csg_blocks_.size() > file_csg_base_;
    if (w == "csg") csg(st, toks);
    else if (w == "end") csg_end(st, toks);
    else if (const auto kind = w == "mesh" ? ShapeKind::Mesh : shape_from_word(w)) {
        if (in_csg_block) csg_child(st, toks, *kind);
        else one_pass_shape(st, toks, *kind);
    } else if (in_csg_block && std::find(kStatementWords.begin(), kStatementWords.end(), w) != kStatementWords.end())
        st.fail_here("'" + std::string(w) + "' cannot be inside a csg block (it holds shapes and csg blocks, then 'end')");
    else if (w == "image") image(st, toks);
    else if (w == "ambient") ambient(st, toks);
    else if (w == "background") background(st, toks);
    else if (w == "camera") camera(st, toks);
    else if (w == "light") light(st, toks);
    else if (w == "material") material(st, toks);
    else if (w == "include") include(st, toks, depth);
    else if (w == "key") key(st, toks);

    else {
        const auto near = nearest_name(w, kStatementWords);
        st.fail_here("unknown statement " + quote(w) + (near ? ": did you mean '" + *near + "'?" : std::string()) +
                     " (expected " + kStatementList + ")");
    }
}

}  // namespace scene_reader

using scene_reader::FileText;
using scene_reader::Parser;
using scene_reader::identity_of;
namespace fs = std::filesystem;

Scene load_scene(const std::string& path, const ReadOptions& options) {
    FileText text;
    if (!text.open(fs::path(path))) throw SceneError(SourceLoc{path, 0, 0}, "cannot open scene file");
    if (options.copies) options.copies->push_back(FileCopy{path, std::string(text.text())});
    // Everything reading starts (meshes, their hierarchies) runs in options.jobs threads.
    return Parallelism(options.jobs).run([&] {
        Parser p(options);
        p.scene.path = path;
        p.scene.inputs.push_back(SceneInput{path, "the scene file", {}});
        p.read_top(text.text(), path, identity_of(path), text.mapped());
        p.finish();
        return std::move(p.scene);
    });
}

Scene load_scene(const std::string& path, int jobs) {
    ReadOptions options;
    options.jobs = jobs;
    return load_scene(path, options);
}

Scene parse_scene(std::string_view text, const std::string& name, const ReadOptions& options) {
    return Parallelism(options.jobs).run([&] {
        Parser p(options);
        p.scene.path = name;
        p.read_top(text, name, identity_of(name.empty() ? fs::path("<memory>") : fs::path(name)), false);
        p.finish();
        return std::move(p.scene);
    });
}

Scene parse_scene(std::string_view text, const std::string& name) { return parse_scene(text, name, ReadOptions{}); }

}  // namespace streamrt
