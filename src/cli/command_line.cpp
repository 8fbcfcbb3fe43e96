// cli/command_line.cpp — CLI11 declarations, help layout and one-line parse errors (see command_line.h).
#include "cli/command_line.h"

#include <CLI/CLI.hpp>
#include <memory>
#include <sstream>

#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat::cli {

namespace {

/// Flag names start at column 2, their help at column 25 (a longer name puts it on the next line).
constexpr size_t kHelpColumn = 25;

/// vdbsplat's help: the description (usage line first) instead of CLI11's "Usage:" line.
class HelpLayout : public CLI::Formatter {
public:
    HelpLayout() {
        column_width(kHelpColumn);
        label("Positionals", "arguments");
        label("REQUIRED", "(required)");
    }
    std::string make_usage(const CLI::App*, std::string) const override { return ""; }
    std::string make_description(const CLI::App* app) const override { return app->get_description() + "\n\n"; }
    /// A group: its name and its flags, one blank line between groups.
    std::string make_group(std::string group, bool positional, std::vector<const CLI::Option*> opts) const override {
        std::string out = group + ":\n";
        for (const CLI::Option* o : opts) out += make_option(o, positional);
        return out;
    }
    std::string make_positionals(const CLI::App* app) const override {
        const std::string out = CLI::Formatter::make_positionals(app);
        return out.empty() ? out : out + "\n";
    }
    /// A command in the list of commands: its name and the first line of its description.
    std::string make_subcommand(const CLI::App* sub) const override {
        const std::string d = sub->get_description();
        std::ostringstream out;
        CLI::detail::format_help(out, sub->get_name(), d.substr(0, d.find('\n')), 12);
        return out.str();
    }
};

/// Whether @p top is vdbsplat's app with its commands and none was chosen yet.
bool awaitingCommand(const CLI::App& top) {
    return top.get_require_subcommand_min() > 0 && top.get_subcommands().empty();
}

/// The app that was being parsed when the error came: the chosen command, else @p top.
const CLI::App& commandOf(const CLI::App& top) {
    const auto chosen = top.get_subcommands();
    return chosen.empty() ? top : *chosen.front();
}

/// The declared option of @p app whose name starts CLI11's message @p what ("--lod: …").
std::string flagNamed(const CLI::App& app, const std::string& what) {
    std::string best;
    for (const CLI::Option* o : app.get_options()) {
        const std::string name = o->get_name();
        if (what.rfind(name, 0) == 0 && what.size() > name.size() && (what[name.size()] == ':' || what[name.size()] == ' ') &&
            name.size() > best.size())
            best = name;
    }
    return best;
}

/// An argument no declaration took: an unknown option, or one positional too many.
std::string unexpected(const CLI::App& top, const CLI::App& command) {
    std::vector<std::string> left = command.remaining();
    if (left.empty()) left = top.remaining(true);
    if (left.empty()) return "unexpected argument (see --help)";
    std::string arg = left.front();
    const bool option = arg.size() > 1 && arg[0] == '-';
    if (option && arg.rfind("--", 0) == 0) arg = arg.substr(0, arg.find('='));
    if (awaitingCommand(top) && !option)
        return "unknown command '" + printable(arg) + "' (try: " + top.get_name() + " --help)";
    return (option ? "unknown option '" : "unexpected argument '") + printable(arg) + "' (see --help)";
}

}  // namespace

CLI::Option* addValueFlag(CLI::App& app, const std::string& name, const std::string& value, const std::string& help) {
    return app.add_option(name)
        ->description(help)
        ->type_name(value)
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

CLI::Option* addSwitch(CLI::App& app, const std::string& name, const std::string& help) {
    return app.add_flag(name)->description(help)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

CLI::Option* addPositional(CLI::App& app, const std::string& name, const std::string& help, bool many) {
    CLI::Option* o = app.add_option(name)->description(help)->expected(1);
    if (many) o->allow_extra_args()->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    return o;
}

void useHelpLayout(CLI::App& app) {
    app.formatter(std::make_shared<HelpLayout>());
    app.option_defaults()->group("options");
    app.set_help_flag("-h,--help", "print this help and exit");
}

std::string parseErrorMessage(const CLI::App& top, const CLI::ParseError& e) {
    const CLI::App& command = commandOf(top);
    const std::string what = e.what();
    if (dynamic_cast<const CLI::ExtrasError*>(&e)) return unexpected(top, command);
    if (dynamic_cast<const CLI::RequiredError*>(&e)) {
        if (awaitingCommand(top))
            return top.remaining(true).empty() ? "no command given (try: " + top.get_name() + " --help)"
                                               : unexpected(top, command);
        return what + " (see --help)";
    }
    if (dynamic_cast<const CLI::ArgumentMismatch*>(&e)) {
        const std::string flag = flagNamed(command, what);
        if (!flag.empty()) return flag + ": missing value";
    }
    const std::string flag = flagNamed(command, what);
    return flag.empty() ? what : flag + what.substr(flag.size());
}

void parseWords(CLI::App& app, const Argv& words) {
    Argv reversed;  // CLI11 takes the words last to first
    for (auto w = words.rbegin(); w != words.rend(); ++w) {
        // "--flag=" is an empty value; CLI11 would take the next word as the value instead.
        if (w->size() > 3 && w->rfind("--", 0) == 0 && w->find('=') == w->size() - 1) {
            reversed.push_back("");
            reversed.push_back(w->substr(0, w->size() - 1));
        } else {
            reversed.push_back(*w);
        }
    }
    app.parse(reversed);
}

Args parseAlone(CLI::App& app, const Argv& argv) {
    try {
        parseWords(app, argv);
    } catch (const CLI::ParseError& e) {
        throw Error(parseErrorMessage(app, e));
    }
    return Args(app, argv);
}

}  // namespace vdbsplat::cli
