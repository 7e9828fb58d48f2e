// `sogmm view --serve`: the page on http://127.0.0.1:PORT/ until Ctrl-C.
#pragma once

#include <string>

namespace sogmm::tools {

/// Serves `page` (text/html) on 127.0.0.1:`port` (0: a free port the system
/// picks) with a single-threaded HTTP/1.0 responder: GET or HEAD of / or
/// /index.html gets the page, another path 404, another method 405, a
/// malformed or oversized request 400, a Host header naming neither
/// 127.0.0.1:PORT nor localhost:PORT 403 (a DNS-rebinding page cannot read
/// it). Prints the URL on stdout once listening and returns when SIGINT
/// arrives (a second SIGINT ends the process). A client that sends nothing
/// is dropped after 5 s. Throws Error(Io) when the port cannot be bound.
void serve_page(const std::string& page, int port);

}  // namespace sogmm::tools
