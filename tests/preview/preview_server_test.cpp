// streamrt serve (engine/preview/, docs/preview.md): the server in this process on a port the
// system chooses, spoken to with cpp-httplib's client; the port-in-use case runs the program.
// Waits are for a state to be reached (a frame, an error), never for a time to pass.
#include <doctest/doctest.h>
#include <httplib.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <numbers>
#include <thread>

#include "cli/cli_support.h"
#include "driver/render_job.h"
#include "image/image_io.h"
#include "preview/serve.h"
#include "scene/parser.h"

using namespace streamrt;
using cli_support::Dir;

namespace {

std::string scene_text(const std::string& dir, const std::string& background, const std::string& size = "width=64 height=48 spp=2") {
    return "image " + size + " depth=3 degree=5 output=" + dir + "/out.pfm\n"
           "background " + background + "\n"
           "camera eye=0,1.6,6 look=0,0.8,0 up=0,1,0 fov=40\n"
           "light point pos=-4,7,6 color=0.8,0.8,0.8\n"
           "plane color=0.95,0.85,0.1 checker=0.85,0.1,0.05 cell=1 ambi=1 diff=0.9\n"
           "sphere color=0.9,0.9,0.9 refl=0.6 scale=1 translate=-0.9,1,-1.5\n";
}

/// Polls /status until `done` holds (each poll is a real request); fails after a minute
/// (times STREAMRT_TEST_TIMEOUT_SCALE, which the sanitizer builds raise), which only a hang
/// reaches.
template <class Done>
std::string wait_status(httplib::Client& c, Done done) {
    const char* scale = std::getenv("STREAMRT_TEST_TIMEOUT_SCALE");
    const double seconds = 60.0 * (scale ? std::max(1.0, std::atof(scale)) : 1.0);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                std::chrono::duration<double>(seconds));
    std::string body;
    while (std::chrono::steady_clock::now() < give_up) {
        if (auto r = c.Get("/status"); r && r->status == 200) {
            body = r->body;
            if (done(body)) return body;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    FAIL("status never reached the state waited for; last: " << body);
    return body;
}

/// The integer after "key": in a JSON text (the first one).
long long json_int(const std::string& json, const std::string& key) {
    const auto at = json.find("\"" + key + "\":");
    REQUIRE(at != std::string::npos);
    return std::atoll(json.c_str() + at + key.size() + 3);
}

bool idle(const std::string& s) { return s.find("\"pass\":\"idle\"") != std::string::npos; }

struct Served {
    Dir dir;
    std::string scene;
    std::unique_ptr<preview::PreviewServer> server;
    explicit Served(const std::string& size = "width=64 height=48 spp=2") {
        scene = dir.write("scene.cfg", scene_text(dir.path.string(), "0.35,0.55,0.85", size)).string();
        preview::ServeOptions o;
        o.scene_path = scene;
        o.port = 0;
        o.jobs = 2;
        o.watch_ms = 20;
        server = std::make_unique<preview::PreviewServer>(o);
        server->start();
    }
    httplib::Client client() const {
        httplib::Client c("127.0.0.1", server->port());
        c.set_read_timeout(60, 0);
        return c;
    }
};

/// A render of `scene` through the render job every front end uses (the command line's
/// defaults), as the CLI's PNG holds it.
Framebuffer render_like_cli(const std::string& scene, const std::string& png) {
    RenderOverrides o;
    o.engine = "stream", o.accel = "auto", o.shade = "simd", o.threads = 1;
    o.output = png;
    RenderJob job = build_render_job(std::make_shared<const Scene>(load_scene(scene)), o, false);
    auto prepared = prepare_job(job, job.engine, -1);
    Parallelism par(1);
    const RenderResult r = render_prepared(*prepared, par);
    write_image(png, r.image, display_of(job.render_settings));
    return read_image(png);
}

}  // namespace

TEST_CASE("serve: the page, its script and the picture are served, the full pass is the CLI's picture") {
    Served s;
    auto c = s.client();
    auto page = c.Get("/");
    REQUIRE(page);
    CHECK(page->status == 200);
    CHECK(page->get_header_value("Content-Type").find("text/html") == 0);
    CHECK(page->body.find("id=\"picture\"") != std::string::npos);
    CHECK(page->body.find("src=\"/app.js\"") != std::string::npos);
    // Nothing from the internet: no address of another host anywhere in the page or script.
    auto script = c.Get("/app.js");
    REQUIRE(script);
    CHECK(script->status == 200);
    CHECK(script->body.find("/camera") != std::string::npos);
    for (const std::string& text : {page->body, script->body}) CHECK(text.find("http") == std::string::npos);

    wait_status(c, idle);
    auto frame = c.Get("/frame.png");
    REQUIRE(frame);
    CHECK(frame->status == 200);
    CHECK(frame->get_header_value("Content-Type") == "image/png");
    CHECK(frame->get_header_value("X-Pass") == "full");
    CHECK(frame->get_header_value("X-Samples") == "2");
    const std::string served = (s.dir.path / "served.png").string();
    std::ofstream(served, std::ios::binary) << frame->body;
    const Framebuffer got = read_image(served);
    CHECK(got.width == 64);
    CHECK(got.height == 48);
    const Framebuffer want = render_like_cli(s.scene, (s.dir.path / "cli.png").string());
    REQUIRE(want.width == got.width);
    REQUIRE(want.height == got.height);
    CHECK(std::equal(got.rgb.begin(), got.rgb.end(), want.rgb.begin(), want.rgb.end()));
    // The bytes too: the same encoder on the same pixels.
    CHECK(frame->body == cli_support::slurp(s.dir.path / "cli.png"));
}

TEST_CASE("serve: only the served names answer, no path reaches a file") {
    Served s;
    auto c = s.client();
    for (const char* path : {"/../scene.cfg", "/etc/passwd", "/%2e%2e/scene.cfg", "/%2E%2E%2Fscene.cfg",
                             "/scene.cfg", "//etc/passwd", "/app.js/../../scene.cfg", "/frame.png/..%2f..%2fscene.cfg"}) {
        CAPTURE(path);
        auto r = c.Get(path);
        REQUIRE(r);
        CHECK(r->status == 404);
        CHECK(r->body.find("camera") == std::string::npos);  // the scene's text is never sent
    }
    auto wrong_method = c.Post("/frame.png", "", "text/plain");
    REQUIRE(wrong_method);
    CHECK(wrong_method->status == 405);
}

TEST_CASE("serve: a foreign Host or Origin is refused (403)") {
    Served s;
    auto c = s.client();
    const std::string own = "127.0.0.1:" + std::to_string(s.server->port());
    auto rebound = c.Get("/status", {{"Host", "evil.example:" + std::to_string(s.server->port())}});
    REQUIRE(rebound);
    CHECK(rebound->status == 403);
    auto other_port = c.Get("/", {{"Host", "127.0.0.1:1"}});
    REQUIRE(other_port);
    CHECK(other_port->status == 403);
    auto cross_site = c.Post("/camera", {{"Origin", "http://evil.example"}}, "fov=30", "text/plain");
    REQUIRE(cross_site);
    CHECK(cross_site->status == 403);
    auto null_origin = c.Get("/status", {{"Origin", "null"}});
    REQUIRE(null_origin);
    CHECK(null_origin->status == 403);
    auto own_origin = c.Get("/status", {{"Origin", "http://" + own}});
    REQUIRE(own_origin);
    CHECK(own_origin->status == 200);
    auto localhost = c.Get("/status", {{"Host", "localhost:" + std::to_string(s.server->port())}});
    REQUIRE(localhost);
    CHECK(localhost->status == 200);
}

TEST_CASE("serve: oversized requests are refused and the server answers afterwards") {
    Served s;
    auto c = s.client();
    auto big_header = c.Get("/status", {{"X-Big", std::string(64 * 1024, 'a')}});
    // httplib refuses a header line past its limit: 400, or the connection closed unanswered.
    if (big_header) CHECK((big_header->status == 400 || big_header->status == 431 || big_header->status == 413));
    auto big_body = c.Post("/camera", std::string(200 * 1024, 'x'), "text/plain");
    if (big_body) CHECK(big_body->status == 413);
    auto bad = c.Post("/camera", "fov=abc", "text/plain");
    REQUIRE(bad);
    CHECK(bad->status == 400);
    CHECK(bad->body.find("fov=") != std::string::npos);
    auto after = s.client().Get("/status");
    REQUIRE(after);
    CHECK(after->status == 200);
}

/// Asks for the picture on a socket with a small receive buffer, reads a little of the reply
/// and closes: the server is then still writing, and its next write fails (EPIPE; SIGPIPE if
/// it were not ignored). httplib's client reads into large buffers, which a picture of a few
/// megabytes fits in whole, so the server would never notice the client leave.
void leave_mid_picture(int port, const std::string& host, bool read_first) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    REQUIRE(fd >= 0);
    int small = 4096;
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(std::uint16_t(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    REQUIRE(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0);
    const std::string request = "GET /frame.png HTTP/1.1\r\nHost: " + host + "\r\n\r\n";
    REQUIRE(::send(fd, request.data(), request.size(), 0) == ssize_t(request.size()));
    if (read_first) {
        char buf[1024];
        CHECK(::recv(fd, buf, sizeof buf, 0) > 0);
    }
    // Unread bytes at close: the kernel resets the connection. Without (gone before the
    // reply): the first write of the reply is answered by a reset, and the next one fails.
    ::close(fd);
}

TEST_CASE("serve: a client gone mid-picture does not stop the server") {
    // SIGPIPE's default action, whatever this process inherited: the server must set its own.
    std::signal(SIGPIPE, SIG_DFL);
    Served s("width=1200 height=900 spp=2");
    auto c = s.client();
    wait_status(c, idle);
    const std::string host = "127.0.0.1:" + std::to_string(s.server->port());
    for (int i = 0; i < 6; ++i) leave_mid_picture(s.server->port(), host, i % 2 == 0);
    auto after = c.Get("/frame.png");
    REQUIRE(after);
    CHECK(after->status == 200);
    CHECK(after->body.size() > 100000);  // a picture big enough to outlast the small buffer
}

TEST_CASE("serve: a saved scene re-renders, a broken one shows file:line:col and keeps the picture") {
    Served s;
    auto c = s.client();
    const long long first = json_int(wait_status(c, idle), "frame");
    // A new version of the file (another background): a new picture.
    {
        std::ofstream(s.scene + ".new") << scene_text(s.dir.path.string(), "0.9,0.2,0.2");
        std::filesystem::rename(s.scene + ".new", s.scene);
    }
    const std::string after = wait_status(c, [&](const std::string& b) { return idle(b) && json_int(b, "frame") > first; });
    CHECK(after.find("\"error\":\"\"") != std::string::npos);
    const long long second = json_int(after, "frame");
    // A broken save: the error with its place, the picture kept.
    {
        std::ofstream(s.scene + ".new") << scene_text(s.dir.path.string(), "0.9,0.2,0.2") << "sphere radius=oops\n";
        std::filesystem::rename(s.scene + ".new", s.scene);
    }
    const std::string broken = wait_status(c, [](const std::string& b) { return b.find("\"error\":\"\"") == std::string::npos; });
    CHECK(broken.find("scene.cfg:7:") != std::string::npos);
    CHECK(json_int(broken, "frame") == second);
    auto kept = c.Get("/frame.png");
    REQUIRE(kept);
    CHECK(kept->status == 200);
    // The next good save clears it.
    {
        std::ofstream(s.scene + ".new") << scene_text(s.dir.path.string(), "0.2,0.9,0.2");
        std::filesystem::rename(s.scene + ".new", s.scene);
    }
    const std::string fixed = wait_status(c, [&](const std::string& b) {
        return idle(b) && json_int(b, "frame") > second && b.find("\"error\":\"\"") != std::string::npos;
    });
    CHECK(json_int(fixed, "frame") > second);
}

TEST_CASE("serve: the camera moves, the settings change, the full-size render is the CLI's file") {
    Served s;
    auto c = s.client();
    const std::string before = wait_status(c, idle);
    CHECK(before.find("\"camera_statement\":\"camera eye=0,1.6,6 look=0,0.8,0 up=0,1,0 fov=40\"") != std::string::npos);
    auto moved = c.Post("/camera", "eye=1,2,5&look=0,0.8,0&fov=35", "text/plain");
    REQUIRE(moved);
    CHECK(moved->status == 200);
    const std::string after = wait_status(c, [&](const std::string& b) {
        return idle(b) && json_int(b, "frame") > json_int(before, "frame");
    });
    CHECK(after.find("camera eye=1,2,5 look=0,0.8,0 up=0,1,0 fov=35") != std::string::npos);
    auto bad_camera = c.Post("/camera", "eye=0,0.8,0&look=0,0.8,0", "text/plain");
    REQUIRE(bad_camera);
    CHECK(bad_camera->status == 400);
    auto bad_setting = c.Post("/settings", "degree=9", "text/plain");
    REQUIRE(bad_setting);
    CHECK(bad_setting->status == 400);
    CHECK(bad_setting->body.find("degree") != std::string::npos);
    // Back to the scene's own camera, then the full-size file against the command line's.
    const auto cam = c.Post("/camera", "eye=0,1.6,6&look=0,0.8,0&up=0,1,0&fov=40", "text/plain");
    REQUIRE(cam);
    auto full = c.Post("/render-full", "", "text/plain");
    REQUIRE(full);
    CHECK(full->status == 200);
    const auto cli = cli_support::run_streamrt(cli_support::q(s.scene) + " -q -j 2 -o " +
                                               cli_support::q(s.dir.path / "cli.pfm"));
    REQUIRE(cli.code == 0);
    CHECK(cli_support::slurp(s.dir.path / "out.pfm") == cli_support::slurp(s.dir.path / "cli.pfm"));
}

TEST_CASE("serve: the views: the sample map of an adaptive scene, the stream engine's profile") {
    Served plain;
    auto c = plain.client();
    const std::string st = wait_status(c, idle);
    CHECK(st.find("\"sample_map\":false") != std::string::npos);
    CHECK(st.find("\"profile\":\"\"") == std::string::npos);  // the stream engine's full pass has one
    auto none = c.Get("/samples.png");
    REQUIRE(none);
    CHECK(none->status == 503);

    Served adaptive("width=64 height=48 spp=16 adaptive=0.05");
    auto a = adaptive.client();
    const std::string ast = wait_status(a, idle);
    CHECK(ast.find("\"sample_map\":true") != std::string::npos);
    CHECK(ast.find("\"estimated_error\":null") == std::string::npos);
    auto map = a.Get("/samples.png");
    REQUIRE(map);
    CHECK(map->status == 200);
    const std::string file = (adaptive.dir.path / "samples.png").string();
    std::ofstream(file, std::ios::binary) << map->body;
    const Framebuffer grey = read_image(file);
    CHECK(grey.width == 64);
    CHECK(grey.height == 48);
    // Pixels of the sphere's edge take more samples than the sky's: not one flat grey.
    const auto [lo, hi] = std::minmax_element(grey.rgb.begin(), grey.rgb.end());
    CHECK(*lo < *hi);
    CHECK(*hi == 1.0f);  // the most samples any pixel took
}

TEST_CASE("serve: a port in use is one line and exit status 1") {
    Served s;
    const auto r = cli_support::run_streamrt("serve " + cli_support::q(s.scene) + " --port " +
                                             std::to_string(s.server->port()));
    CHECK(r.code == 1);
    cli_support::check_one_line_error(r, "is in use");
    const auto missing = cli_support::run_streamrt("serve " + cli_support::q(s.dir.path / "none.cfg") + " --port 0");
    CHECK(missing.code == 2);
}

TEST_CASE("serve: an explicit-form camera is read back as the look-at camera with its eye, screen centre and up") {
    // docs/scene-format.md's example: eye at (0, 1 + 2 sin 10deg, 6 + 2 cos 10deg), screen
    // centre (0, 1, 6), tilted 10 degrees down; ry / df = 0.75 / 2 is tan(fov / 2).
    const Scene scene = parse_scene("image width=64 height=48\ncamera rx=1 ry=0.75 df=2 rotate_x=-10 translate=0,1,6\n",
                                    "explicit.cfg");
    const preview::ViewCamera v = preview::view_of(scene.camera, 64, 48);
    const double a = 10.0 * std::numbers::pi / 180.0;
    CHECK(v.eye.x == doctest::Approx(0.0));
    CHECK(v.eye.y == doctest::Approx(1.0 + 2.0 * std::sin(a)));
    CHECK(v.eye.z == doctest::Approx(6.0 + 2.0 * std::cos(a)));
    CHECK(v.look.y == doctest::Approx(1.0));
    CHECK(v.look.z == doctest::Approx(6.0));
    CHECK(v.up.y == doctest::Approx(std::cos(a)));
    CHECK(v.up.z == doctest::Approx(-std::sin(a)));
    CHECK(v.fov == doctest::Approx(2.0 * std::atan(0.75 / 2.0) * 180.0 / std::numbers::pi));
    CHECK(preview::camera_statement(v, scene.camera).rfind("camera eye=0,1.3473,7.96962 look=0,1,6 ", 0) == 0);
}
