// libstreamrt_http.so: Debian's cpp-httplib behind the plain table of preview/http_transport.h,
// loaded by preview/serve.cpp for `streamrt serve` only. httplib parses every request and
// writes every reply; the engine side decides what each one gets.
#include <httplib.h>

#include "preview/http_transport.h"

namespace {

using streamrt::HttpExchange;

struct Server {
    httplib::Server http;
    streamrt::HttpHandlers handlers;
};

/// The request's fields into `x` (pointers into `req`, alive for the call).
void fill_request(const httplib::Request& req, HttpExchange& x, const std::string& host, const std::string& origin) {
    x.method = req.method.c_str();
    x.path = req.path.c_str();
    x.host = host.c_str();
    x.origin = origin.c_str();
    x.body = req.body.data();
    x.body_size = req.body.size();
}

/// The handler's reply into `res`, then released.
void take_reply(HttpExchange& x, httplib::Response& res) {
    res.status = x.status > 0 ? x.status : 500;
    for (const char* p = x.headers; p && *p;) {
        const char* end = p;
        while (*end && *end != '\n') ++end;
        const std::string line(p, end);
        if (const auto colon = line.find(": "); colon != std::string::npos)
            res.set_header(line.substr(0, colon), line.substr(colon + 2));
        p = *end ? end + 1 : end;
    }
    res.set_content(std::string(x.reply_body, x.reply_size), x.content_type);
    if (x.release) x.release(x.reply_owner);
}

void* create(const streamrt::HttpHandlers* handlers) {
    auto* s = new Server;
    s->handlers = *handlers;
    s->http.set_payload_max_length(handlers->max_body);
    // httplib's default also sets SO_REUSEPORT, which lets a second server bind a port one
    // already listens on (and share its connections): a port in use must be an error.
    // SO_REUSEADDR alone still lets a restarted server bind past the old one's TIME_WAIT.
    s->http.set_socket_options([](socket_t sock) {
        int yes = 1;
        ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });
    // A client that stops reading or writing holds a worker for seconds at most.
    s->http.set_read_timeout(5, 0);
    s->http.set_write_timeout(5, 0);
    s->http.set_pre_routing_handler([s](const httplib::Request& req, httplib::Response& res) {
        const std::string host = req.get_header_value("Host"), origin = req.get_header_value("Origin");
        HttpExchange x;
        fill_request(req, x, host, origin);
        x.body = "", x.body_size = 0;  // not read yet
        s->handlers.guard(s->handlers.user, &x);
        if (x.status == 0) return httplib::Server::HandlerResponse::Unhandled;
        take_reply(x, res);
        return httplib::Server::HandlerResponse::Handled;
    });
    const auto handle = [s](const httplib::Request& req, httplib::Response& res) {
        const std::string host = req.get_header_value("Host"), origin = req.get_header_value("Origin");
        HttpExchange x;
        fill_request(req, x, host, origin);
        s->handlers.handle(s->handlers.user, &x);
        take_reply(x, res);
    };
    s->http.Get(".*", handle);
    s->http.Post(".*", handle);
    return s;
}

int bind(void* server, const char* host, int port) {
    auto* s = static_cast<Server*>(server);
    if (port == 0) return s->http.bind_to_any_port(host);
    return s->http.bind_to_port(host, port) ? port : -1;
}

bool listen(void* server) { return static_cast<Server*>(server)->http.listen_after_bind(); }

void stop(void* server) { static_cast<Server*>(server)->http.stop(); }

void destroy(void* server) { delete static_cast<Server*>(server); }

constexpr streamrt::HttpServerTable kTable{streamrt::kHttpServerVersion, &create, &bind, &listen, &stop, &destroy};

}  // namespace

extern "C" __attribute__((visibility("default"))) const streamrt::HttpServerTable* streamrt_http_server() {
    return &kTable;
}
