// cli/args.h — a small strict command-line parser shared by every subcommand.
// Owns: splitting "--flag value" / "--flag=value" / "-o value" / switches /
// positionals, rejecting unknown or repeated flags and missing values with a
// one-line Error that names the flag.
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace vdbsplat::cli {

class Args {
public:
    /// @param valueFlags flags that take a value (e.g. "--size", "-o")
    /// @param switches   flags without a value (e.g. "-v", "--show-primitives")
    /// @throw Error for an unknown flag, a repeated flag, or a flag missing its value.
    Args(const std::vector<std::string>& argv, const std::set<std::string>& valueFlags,
         const std::set<std::string>& switches);

    bool has(const std::string& flag) const { return values_.count(flag) || switches_.count(flag); }
    std::optional<std::string> get(const std::string& flag) const;
    std::string getOr(const std::string& flag, const std::string& fallback) const;
    /// @throw Error "<flag> is required" when absent.
    std::string require(const std::string& flag) const;
    const std::vector<std::string>& positionals() const { return positionals_; }
    /// @brief The single positional argument; @throw Error naming @p what when there is not exactly one.
    std::string onePositional(const std::string& what) const;
    bool wantsHelp() const { return help_; }

private:
    std::map<std::string, std::string> values_;
    std::set<std::string> switches_;
    std::vector<std::string> positionals_;
    bool help_ = false;
};

}  // namespace vdbsplat::cli
