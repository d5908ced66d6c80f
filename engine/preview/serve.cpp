// `streamrt serve` (preview/serve.h): the routes, the checks every request passes first,
// the file watch and the command.
#include "preview/serve.h"

#include <CLI/CLI.hpp>
#include <sys/stat.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <vector>

#include "core/error.h"
#include "core/module_loader.h"
#include "scene/parser.h"

namespace streamrt::preview {

namespace {

/// Set by SIGINT/SIGTERM while serving: a signal handler can only reach a global.
std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop.store(true); }

bool is_loopback(const std::string& host) {
    return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (const unsigned char c : s) {
        if (c == '"' || c == '\\') out += '\\', out += char(c);
        else if (c == '\n') out += "\\n";
        else if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
        } else out += char(c);
    }
    return out + "\"";
}

std::string json_number(double v) {
    if (!std::isfinite(v)) return "null";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

std::string json_vec(const glm::dvec3& v) {
    return "[" + json_number(v.x) + "," + json_number(v.y) + "," + json_number(v.z) + "]";
}

Reply text(int status, const std::string& body) {
    Reply r;
    r.status = status;
    r.body = body + "\n";
    return r;
}

/// "key=value&key=value" (the page's form encoding, values without escapes): the pairs, or
/// UsageError naming what is wrong.
std::map<std::string, std::string> parse_pairs(const std::string& body) {
    std::map<std::string, std::string> out;
    std::size_t at = 0;
    while (at < body.size()) {
        std::size_t end = body.find('&', at);
        if (end == std::string::npos) end = body.size();
        const std::string pair = body.substr(at, end - at);
        at = end + 1;
        if (pair.empty() || pair == "\n") continue;
        const std::size_t eq = pair.find('=');
        if (eq == std::string::npos || eq == 0) throw UsageError("expected key=value, got " + quote(pair));
        out[pair.substr(0, eq)] = pair.substr(eq + 1);
    }
    return out;
}

double parse_number(const std::string& key, const std::string& v) {
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(x))
        throw UsageError(key + "=" + quote(v) + ": not a number");
    return x;
}

glm::dvec3 parse_vec(const std::string& key, const std::string& v) {
    glm::dvec3 out;
    std::size_t at = 0;
    for (int i = 0; i < 3; ++i) {
        const std::size_t comma = i < 2 ? v.find(',', at) : v.size();
        if (comma == std::string::npos) throw UsageError(key + "=" + quote(v) + ": expected x,y,z");
        out[i] = parse_number(key, v.substr(at, comma - at));
        at = comma + 1;
    }
    return out;
}

std::optional<int> parse_optional_int(const std::string& key, const std::string& v) {
    if (v.empty()) return std::nullopt;  // the scene's own
    const double x = parse_number(key, v);
    if (x != std::floor(x) || std::abs(x) > 1e9) throw UsageError(key + "=" + quote(v) + ": not an integer");
    return int(x);
}

void fill(HttpExchange* x, Reply&& reply) {
    auto* owned = new Reply(std::move(reply));
    x->status = owned->status;
    x->content_type = owned->type.c_str();
    x->reply_body = owned->body.data();
    x->reply_size = owned->body.size();
    x->headers = owned->headers.c_str();
    x->reply_owner = owned;
    x->release = [](void* p) { delete static_cast<Reply*>(p); };
}

void guard_request(void* user, HttpExchange* x) {
    const Reply r = static_cast<PreviewServer*>(user)->guard(x->method, x->path, x->host, x->origin);
    if (r.status != 0) fill(x, Reply(r));
}

void handle_request(void* user, HttpExchange* x) {
    try {
        fill(x, static_cast<PreviewServer*>(user)->handle(x->method, x->path, std::string(x->body, x->body_size)));
    } catch (const std::exception& e) {
        fill(x, text(500, e.what()));
    }
}

/// What identifies a version of a file: a save changes one of them (a new inode when the
/// editor writes a new file and renames it over the old one).
struct FileStamp {
    long long mtime_ns = -1, size = -1;
    unsigned long long inode = 0;
    bool operator==(const FileStamp&) const = default;
};

FileStamp stamp_of(const std::string& path) {
    struct stat st{};
    if (::stat(path.c_str(), &st) != 0) return {};
    return {static_cast<long long>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec,
            static_cast<long long>(st.st_size), static_cast<unsigned long long>(st.st_ino)};
}

std::vector<std::string> input_paths(const Scene& scene) {
    std::vector<std::string> out;
    for (const SceneInput& in : scene.inputs) out.push_back(in.path);
    if (out.empty()) out.push_back(scene.path);
    return out;
}

}  // namespace

PreviewServer::PreviewServer(const ServeOptions& options) : options_(options) {
    // A client gone mid-reply must not end the process (httplib writes without MSG_NOSIGNAL):
    // the write fails instead, and that connection alone ends.
    std::signal(SIGPIPE, SIG_IGN);
    auto scene = std::make_shared<const Scene>(load_scene(options_.scene_path, options_.jobs));
    watched_ = input_paths(*scene);
    const auto module = load_module_table<HttpServerTable>(kHttpModuleFile, kHttpServerSymbol, kHttpServerVersion, false);
    if (!module.table)
        throw RenderError("serve: this streamrt has no HTTP server (" + module.error +
                          "; it is built when CMake finds Debian's libcpp-httplib-dev)");
    http_ = module.table;
    HttpHandlers handlers;
    handlers.user = this;
    handlers.guard = &guard_request;
    handlers.handle = &handle_request;
    handlers.max_body = 64 * 1024;  // the page posts a few numbers: anything large is refused (413)
    server_ = http_->create(&handlers);
    errno = 0;
    port_ = http_->bind(server_, options_.host.c_str(), options_.port);
    if (port_ <= 0) {
        const int err = errno;
        http_->destroy(server_);
        server_ = nullptr;
        const std::string where = options_.host + ":" + std::to_string(options_.port);
        if (err == EADDRINUSE)
            throw RenderError("serve: port " + std::to_string(options_.port) + " on " + options_.host +
                              " is in use (another --port, or --port 0 for any free one)");
        throw RenderError("serve: cannot listen on " + where + (err ? std::string(": ") + std::strerror(err) : ""));
    }
    loop_ = std::make_unique<RenderLoop>(std::move(scene), options_.jobs);
}

PreviewServer::~PreviewServer() {
    stop();
    if (server_) http_->destroy(server_);
}

std::string PreviewServer::url() const {
    const bool v6 = options_.host.find(':') != std::string::npos;
    return "http://" + (v6 ? "[" + options_.host + "]" : options_.host) + ":" + std::to_string(port_) + "/";
}

void PreviewServer::start() {
    loop_->start();
    watch_thread_ = std::thread([this] { watch(); });
    listen_thread_ = std::thread([this] { http_->listen(server_); });
}

void PreviewServer::stop() {
    if (stopping_.exchange(true)) return;
    // Renders first: a request waiting for the full-size picture is answered (with the
    // stop), so that the server's workers, which httplib joins when it stops, are free.
    if (loop_) loop_->stop();
    if (server_) http_->stop(server_);
    if (listen_thread_.joinable()) listen_thread_.join();
    if (watch_thread_.joinable()) watch_thread_.join();
}

Reply PreviewServer::guard(const std::string& method, const std::string& path, const std::string& host,
                           const std::string& origin) const {
    (void)method, (void)path;
    // DNS rebinding: a page of another site whose name was made to resolve to 127.0.0.1
    // reaches this port with its own name in Host. Only the names this server is reached by
    // are answered.
    const std::string port = ":" + std::to_string(port_);
    std::vector<std::string> hosts{"127.0.0.1" + port, "localhost" + port, "[::1]" + port};
    const bool v6 = options_.host.find(':') != std::string::npos;
    hosts.push_back((v6 ? "[" + options_.host + "]" : options_.host) + port);
    bool host_ok = false;
    for (const std::string& h : hosts) host_ok = host_ok || host == h;
    if (!host_ok) return text(403, "forbidden: Host " + quote(host) + " is not this server's");
    // Cross-site requests: a browser names the page that sent them in Origin. Only this
    // server's own page may use it (its requests carry http://HOST:PORT, or no Origin).
    if (!origin.empty() && origin != "http://" + host) return text(403, "forbidden: Origin " + quote(origin) + " is not this server's");
    Reply pass;
    pass.status = 0;
    return pass;
}

Reply PreviewServer::status_reply() const {
    const LoopStatus s = loop_->status();
    const auto frame = loop_->frame();
    std::string j = "{";
    j += "\"frame\":" + std::to_string(s.frame);
    j += ",\"pass\":" + json_string(s.pass);
    j += ",\"progress\":" + json_number(s.tiles_total > 0 ? double(s.tiles_done) / s.tiles_total : 0.0);
    j += ",\"error\":" + json_string(s.error);
    if (frame) {
        j += ",\"picture\":{\"width\":" + std::to_string(frame->width) + ",\"height\":" + std::to_string(frame->height);
        j += ",\"spp\":" + std::to_string(frame->spp) + ",\"full\":" + (frame->full ? "true" : "false");
        j += ",\"seconds\":" + json_number(frame->seconds) + ",\"rays\":" + std::to_string(frame->rays);
        j += ",\"rays_per_second\":" + json_number(frame->rays_per_second);
        j += ",\"estimated_error\":" + (frame->estimated_error ? json_number(*frame->estimated_error) : "null");
        j += ",\"sample_map\":" + std::string(frame->samples_png.empty() ? "false" : "true");
        j += ",\"profile\":" + json_string(frame->profile);
        j += "}";
    }
    j += ",\"camera\":{\"eye\":" + json_vec(s.camera.eye) + ",\"look\":" + json_vec(s.camera.look) +
         ",\"up\":" + json_vec(s.camera.up) + ",\"fov\":" + json_number(s.camera.fov) + "}";
    j += ",\"camera_statement\":" + json_string(s.camera_statement);
    j += ",\"width\":" + std::to_string(s.width) + ",\"height\":" + std::to_string(s.height);
    j += ",\"spp\":" + std::to_string(s.spp) + ",\"degree\":" + std::to_string(s.degree);
    j += ",\"engine\":" + json_string(s.engine);
    j += ",\"scene\":" + json_string(options_.scene_path) + ",\"output\":" + json_string(s.output);
    j += ",\"written\":" + json_string(s.last_written);
    j += "}";
    Reply r;
    r.type = "application/json";
    r.body = j;
    r.headers = "Cache-Control: no-store\n";
    return r;
}

Reply PreviewServer::handle(const std::string& method, const std::string& path, const std::string& body) {
    // The served set is these names and nothing else: no path is ever looked up as a file.
    static const std::map<std::string, std::string> kRoutes{{"/", "GET"},           {"/index.html", "GET"},
                                                            {"/app.js", "GET"},     {"/frame.png", "GET"},
                                                            {"/status", "GET"},     {"/camera", "POST"},
                                                            {"/settings", "POST"},  {"/render-full", "POST"},
                                                            {"/samples.png", "GET"}};
    const auto route = kRoutes.find(path);
    if (route == kRoutes.end()) return text(404, "not found");
    if (route->second != method) return text(405, "method not allowed: " + route->second + " " + path);
    try {
        if (path == "/" || path == "/index.html") {
            Reply r;
            r.type = "text/html; charset=utf-8";
            r.body = kPageHtml;
            // The page runs its own script and shows its own pictures; nothing else loads.
            r.headers = "Content-Security-Policy: default-src 'none'; script-src 'self'; connect-src 'self'; "
                        "img-src 'self' blob:; style-src 'unsafe-inline'\nX-Frame-Options: DENY\n";
            return r;
        }
        if (path == "/app.js") {
            Reply r;
            r.type = "text/javascript; charset=utf-8";
            r.body = kPageScript;
            return r;
        }
        if (path == "/status") return status_reply();
        if (path == "/frame.png") {
            const auto frame = loop_->frame();
            if (!frame) return text(503, "no picture yet");
            Reply r;
            r.type = "image/png";
            r.body = frame->png;
            char h[512];
            std::snprintf(h, sizeof h,
                          "Cache-Control: no-store\nX-Frame: %llu\nX-Pass: %s\nX-Samples: %d\nX-Rays-Per-Second: %.6g\n"
                          "X-Seconds: %.6g\n",
                          static_cast<unsigned long long>(frame->id), frame->full ? "full" : "quick", frame->spp,
                          frame->rays_per_second, frame->seconds);
            r.headers = h;
            return r;
        }
        if (path == "/samples.png") {
            const auto frame = loop_->frame();
            if (!frame || frame->samples_png.empty())
                return text(503, "no sample map: the full pass of an adaptive scene (image adaptive=) has one");
            Reply r;
            r.type = "image/png";
            r.body = frame->samples_png;
            r.headers = "Cache-Control: no-store\nX-Frame: " + std::to_string(frame->id) + "\n";
            return r;
        }
        if (path == "/camera") {
            const auto pairs = parse_pairs(body);
            ViewCamera v = loop_->status().camera;
            bool moving = false;
            for (const auto& [key, value] : pairs) {
                if (key == "eye") v.eye = parse_vec(key, value);
                else if (key == "look") v.look = parse_vec(key, value);
                else if (key == "up") v.up = parse_vec(key, value);
                else if (key == "fov") v.fov = parse_number(key, value);
                else if (key == "moving") moving = value == "1" || value == "true";
                else throw UsageError("unknown key " + quote(key) + " (eye, look, up, fov, moving)");
            }
            // The scene format's own rules for a look-at camera (docs/scene-format.md).
            if (!(v.fov > 0 && v.fov < 180)) throw UsageError("fov must be in (0, 180)");
            const glm::dvec3 forward = v.look - v.eye;
            if (glm::length(forward) == 0) throw UsageError("look must differ from eye");
            if (glm::length(v.up) == 0 || glm::length(glm::cross(glm::normalize(forward), v.up)) < 1e-9)
                throw UsageError("up must be non-zero and not parallel to look - eye");
            loop_->set_camera(v, moving);
            return text(200, "ok");
        }
        if (path == "/settings") {
            ViewSettings s = loop_->status().settings;
            for (const auto& [key, value] : parse_pairs(body)) {
                if (key == "degree") s.degree = parse_optional_int(key, value);
                else if (key == "spp") s.spp = parse_optional_int(key, value);
                else if (key == "engine") s.engine = value.empty() ? std::nullopt : std::optional<std::string>(value);
                else throw UsageError("unknown key " + quote(key) + " (degree, spp, engine)");
            }
            loop_->set_settings(s);
            return text(200, "ok");
        }
        if (path == "/render-full") return text(200, "written " + loop_->render_full());
    } catch (const UsageError& e) {
        return text(400, e.what());
    } catch (const SceneError& e) {
        return text(400, e.what());
    } catch (const std::exception& e) {
        return text(500, e.what());
    }
    return text(404, "not found");
}

void PreviewServer::watch() {
    std::vector<FileStamp> stamps;
    for (const std::string& p : watched_) stamps.push_back(stamp_of(p));
    while (!stopping_.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(options_.watch_ms));
        bool changed = false;
        for (std::size_t i = 0; i < watched_.size(); ++i) {
            const FileStamp now = stamp_of(watched_[i]);
            if (!(now == stamps[i])) changed = true, stamps[i] = now;
        }
        if (!changed) continue;
        try {
            auto scene = std::make_shared<const Scene>(load_scene(options_.scene_path, options_.jobs));
            // A new include or mesh is watched from now on.
            watched_ = input_paths(*scene);
            stamps.clear();
            for (const std::string& p : watched_) stamps.push_back(stamp_of(p));
            loop_->set_scene(std::move(scene));
        } catch (const std::exception& e) {
            // The last good picture stays; the page shows the error over it. The files the
            // last good scene read are still watched: the next save of any is read again.
            loop_->set_error(e.what());
        }
    }
}

int run_serve(int argc, char** argv) {
    ServeOptions opt;
    CLI::App app{"streamrt serve: a live preview of a scene in the browser (docs/preview.md)", "streamrt serve"};
    app.add_option("scene", opt.scene_path, "Scene file (.cfg)")->required();
    app.add_option("--port", opt.port, "TCP port (default 8080; 0: any free port)")->check(CLI::Range(0, 65535));
    app.add_option("--host", opt.host, "Address to listen on (default 127.0.0.1: this machine only)");
    app.add_option("-j,--jobs", opt.jobs, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
    std::vector<std::string> args;
    for (int i = argc - 1; i >= 1; --i) args.emplace_back(argv[i]);
    try {
        app.parse(args);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        throw UsageError(std::string("serve: ") + e.what() + " (see streamrt serve --help)");
    }
    g_stop.store(false);
    std::signal(SIGINT, on_stop_signal);
    std::signal(SIGTERM, on_stop_signal);
    PreviewServer server(opt);
    std::printf("streamrt serve: %s\n", server.url().c_str());
    std::fflush(stdout);
    if (!is_loopback(opt.host))
        std::fprintf(stderr, "streamrt serve: warning: listening on %s, not this machine's loopback: other machines "
                             "may reach the preview\n", opt.host.c_str());
    server.start();
    while (!g_stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    server.stop();
    std::printf("streamrt serve: stopped\n");
    return 0;
}

}  // namespace streamrt::preview
