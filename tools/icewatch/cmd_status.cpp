// icewatch status: the latest result from a running icewatchd's HTTP API, with "stale".
#include <iostream>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "core/common/error.hpp"
#include "tools/icewatch/command.hpp"

namespace icewatch::cli {

void addStatusCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand("status", "print the latest result of the running icewatchd");
    auto url = std::make_shared<std::string>("http://127.0.0.1:8088");
    cmd->add_option("--url", *url, "icewatchd's HTTP API")->capture_default_str();
    cmd->callback([&run, url] {
        run = [url] {
            httplib::Client client(*url);
            client.set_connection_timeout(5, 0);
            client.set_read_timeout(10, 0);
            const auto r = client.Get("/v1/latest");
            if (!r) {
                throw Error(kExitUnavailable, *url + ": no answer (" + httplib::to_string(r.error()) +
                                                  "); is icewatchd running?");
            }
            const auto doc = nlohmann::json::parse(r->body, nullptr, false);
            if (r->status == 503) {
                throw Error(kExitTempFail, *url + ": icewatchd has no result yet");
            }
            if (r->status != 200 || !doc.is_object()) {
                throw Error(kExitUnavailable, *url + ": unexpected answer " + std::to_string(r->status));
            }
            std::cout << doc.dump(2) << "\n";
            return kExitOk;
        };
    });
}

}  // namespace icewatch::cli
