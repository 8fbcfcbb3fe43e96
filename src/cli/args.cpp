// cli/args.cpp — strict flag parsing (see args.h).
#include "cli/args.h"

#include "util/error.h"

namespace vdbsplat::cli {

Args::Args(const std::vector<std::string>& argv, const std::set<std::string>& valueFlags,
           const std::set<std::string>& switches) {
    for (size_t i = 0; i < argv.size(); ++i) {
        std::string arg = argv[i];
        if (arg == "--help" || arg == "-h") { help_ = true; continue; }
        if (arg.size() < 2 || arg[0] != '-' || (arg[1] >= '0' && arg[1] <= '9') || arg[1] == '.') {
            positionals_.push_back(arg);
            continue;
        }
        std::optional<std::string> inlineValue;
        if (const size_t eq = arg.find('='); arg.rfind("--", 0) == 0 && eq != std::string::npos) {
            inlineValue = arg.substr(eq + 1);
            arg = arg.substr(0, eq);
        }
        if (valueFlags.count(arg)) {
            if (values_.count(arg)) throw Error(arg + ": given more than once");
            if (inlineValue) { values_[arg] = *inlineValue; continue; }
            if (i + 1 >= argv.size()) throw Error(arg + ": missing value");
            values_[arg] = argv[++i];
        } else if (switches.count(arg) && !inlineValue) {
            switches_.insert(arg);
        } else {
            throw Error("unknown option '" + arg + "' (see --help)");
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
    if (positionals_.size() != 1)
        throw Error(positionals_.empty() ? "missing " + what + " (see --help)"
                                         : "expected one " + what + ", got " + std::to_string(positionals_.size()));
    return positionals_.front();
}

}  // namespace vdbsplat::cli
