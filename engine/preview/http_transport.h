#pragma once
// The HTTP module's table (engine/modules/http_server.cpp, built as libstreamrt_http.so when
// CMake finds Debian's cpp-httplib, and loaded by preview/serve.cpp for `streamrt serve`
// only): a server in plain types. cpp-httplib, and the OpenSSL, zlib and Brotli libraries
// Debian builds it with, are then loaded by the one command that serves pages, never at the
// start of a render (docs/architecture.md, "Modules loaded on first use").
#include <cstddef>

namespace streamrt {

/// One request and, once the handler has run, its reply. The request's strings belong to
/// the module and live for the call; the reply's strings belong to the handler, which keeps
/// them alive until the module calls `release(reply_owner)` (after copying them).
struct HttpExchange {
    // The request, as httplib parsed it (the path percent-decoded, without the query).
    const char* method = "";
    const char* path = "";
    const char* host = "";    ///< the Host header ("" when absent)
    const char* origin = "";  ///< the Origin header ("" when absent)
    const char* body = "";
    std::size_t body_size = 0;
    // The reply.
    int status = 0;  ///< 0 from the guard: let the request through
    const char* content_type = "text/plain";
    const char* reply_body = "";
    std::size_t reply_size = 0;
    /// Extra headers as "Name: value\n" lines ("" for none).
    const char* headers = "";
    void* reply_owner = nullptr;
    void (*release)(void* reply_owner) = nullptr;
};

/// What the engine side gives the server.
struct HttpHandlers {
    void* user = nullptr;
    /// Runs first, for every request, before its body is read (httplib's pre-routing): a
    /// non-zero status refuses the request with that reply.
    void (*guard)(void* user, HttpExchange* x) = nullptr;
    /// A GET or POST the guard let through (the body read, at most max_body bytes).
    void (*handle)(void* user, HttpExchange* x) = nullptr;
    std::size_t max_body = 64 * 1024;
};

struct HttpServerTable {
    int version;
    /// A server with its handlers (copied), not yet listening.
    void* (*create)(const HttpHandlers* handlers);
    /// Binds `host`:`port` (0: a port the system chooses); the port bound, or -1.
    int (*bind)(void* server, const char* host, int port);
    /// Serves until `stop`; false when it could not.
    bool (*listen)(void* server);
    /// Stops listening (any thread); listen returns.
    void (*stop)(void* server);
    void (*destroy)(void* server);
};

inline constexpr int kHttpServerVersion = 1;
inline constexpr const char* kHttpModuleFile = "libstreamrt_http.so";
inline constexpr const char* kHttpServerSymbol = "streamrt_http_server";

}  // namespace streamrt
