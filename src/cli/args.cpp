// cli/args.cpp — a parsed CLI::App read back by flag name (see args.h).
#include "cli/args.h"

#include <CLI/App.hpp>

#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat::cli {

namespace {

bool isSwitch(const CLI::Option& o) { return o.get_expected_max() == 0; }

}  // namespace

Args::Args(const CLI::App& app, std::vector<std::string> words) : words_(std::move(words)) {
    for (const CLI::Option* o : app.get_options()) {
        if (o->count() == 0 || o == app.get_help_ptr()) continue;
        const std::string name = o->get_name();
        const CLI::results_t& given = o->results();
        if (o->get_positional()) {
            positionals_.insert(positionals_.end(), given.begin(), given.end());
        } else if (isSwitch(*o)) {
            for (const std::string& v : given)
                if (v != "true") throw Error(name + ": takes no value, got '" + printable(v) + "'");
            switches_.insert(name);
        } else {
            if (given.size() > 1) throw Error(name + ": given more than once");
            values_[name] = given.front();
        }
    }
}

std::optional<std::string> Args::get(const std::string& flag) const {
    const auto it = values_.find(flag);
    if (it == values_.end()) return std::nullopt;
    return it->second;
}

std::string Args::getOr(const std::string& flag, const std::string& fallback) const {
    return get(flag).value_or(fallback);
}

std::string Args::require(const std::string& flag) const {
    const auto v = get(flag);
    if (!v) throw Error(flag + " is required (see --help)");
    return *v;
}

std::string Args::onePositional(const std::string& what) const {
    if (positionals_.empty()) throw Error("missing " + what + " (see --help)");
    if (positionals_.size() > 1)
        throw Error("expected one " + what + ", got " + std::to_string(positionals_.size()));
    return positionals_.front();
}

}  // namespace vdbsplat::cli
