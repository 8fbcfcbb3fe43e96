// cli/args.h — what CLI11 parsed for one command, by flag name.
// Owns: reading a parsed CLI::App back into flag → value, switches and positionals (the
// commands look their flags up by the name they were declared with, command_line.h), and
// the checks CLI11 leaves to us: a value flag given twice and a switch given a value are
// errors that name the flag.
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace vdbsplat::cli {

class Args {
public:
    Args() = default;
    /// @brief The flags and positionals @p app parsed (an app after a successful parse());
    /// @p words: the command line after the command name, as given (for a record of it).
    /// @throw Error for a value flag given more than once or a switch given a value.
    explicit Args(const CLI::App& app, std::vector<std::string> words = {});

    bool has(const std::string& flag) const { return values_.count(flag) || switches_.count(flag); }
    std::optional<std::string> get(const std::string& flag) const;
    std::string getOr(const std::string& flag, const std::string& fallback) const;
    /// @throw Error "<flag> is required" when absent.
    std::string require(const std::string& flag) const;
    const std::vector<std::string>& positionals() const { return positionals_; }
    /// The command line after the command name, as given.
    const std::vector<std::string>& words() const { return words_; }
    /// @brief The single positional argument; @throw Error naming @p what when there is none.
    std::string onePositional(const std::string& what) const;

    /// @brief Gives value flag @p flag the value @p value (replacing any), as if it had been parsed.
    void set(const std::string& flag, const std::string& value) { values_[flag] = value; }
    /// @brief Gives switch @p flag, as if it had been parsed.
    void setSwitch(const std::string& flag) { switches_.insert(flag); }

private:
    std::map<std::string, std::string> values_;
    std::set<std::string> switches_;
    std::vector<std::string> positionals_;
    std::vector<std::string> words_;
};

}  // namespace vdbsplat::cli
