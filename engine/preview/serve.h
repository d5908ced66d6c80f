#pragma once
// `streamrt serve SCENE.cfg [--port P] [--host H] [-j N]` (docs/preview.md): a local web
// server whose one page shows the scene as it renders, re-rendered when a file it read is
// saved, with a camera the page moves. The HTTP parsing is Debian's cpp-httplib, in the module
// libstreamrt_http.so (preview/http_transport.h); what each request gets is decided here.
#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "preview/http_transport.h"
#include "preview/render_loop.h"

namespace streamrt::preview {

struct ServeOptions {
    std::string scene_path;
    std::string host = "127.0.0.1";
    int port = 8080;  ///< 0: a port the system chooses
    int jobs = 0;     ///< render threads (<= 0: all cores)
    int watch_ms = 50;  ///< how often the scene's files are looked at (a save shows within ~100 ms)
};

/// The page and its script, built into the program from engine/preview/page.html and app.js.
extern const char* const kPageHtml;
extern const char* const kPageScript;

/// A reply: status, type, body and extra headers ("Name: value\n" lines).
struct Reply {
    int status = 200;
    std::string type = "text/plain; charset=utf-8", body, headers;
};

class PreviewServer {
  public:
    /// Reads the scene (SceneError: exit status 2), loads the HTTP module and binds the
    /// port (RenderError, exit status 1: "port P on H is in use"); serves nothing yet.
    explicit PreviewServer(const ServeOptions& options);
    ~PreviewServer();
    PreviewServer(const PreviewServer&) = delete;
    PreviewServer& operator=(const PreviewServer&) = delete;

    int port() const { return port_; }
    std::string url() const;
    /// Starts the render loop, the file watch and the server's thread.
    void start();
    /// Stops the server, the watch and the renders (the one under way is cancelled).
    void stop();

    /// What a request gets (also called by the tests without a socket).
    Reply guard(const std::string& method, const std::string& path, const std::string& host,
                const std::string& origin) const;
    Reply handle(const std::string& method, const std::string& path, const std::string& body);

    RenderLoop& loop() { return *loop_; }

  private:
    void watch();
    Reply status_reply() const;

    ServeOptions options_;
    const HttpServerTable* http_ = nullptr;
    void* server_ = nullptr;
    int port_ = 0;
    std::unique_ptr<RenderLoop> loop_;
    std::atomic<bool> stopping_{false};
    std::thread listen_thread_, watch_thread_;
    std::vector<std::string> watched_;  ///< the files the last good scene read (watch thread only)
};

/// The sub-command: argv[0] is "serve". Returns the exit status; errors are thrown (one
/// line each, cli/command.cpp reports them).
int run_serve(int argc, char** argv);

}  // namespace streamrt::preview
