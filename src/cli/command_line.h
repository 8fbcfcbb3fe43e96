// cli/command_line.h — declaring a command's flags on CLI11 and parsing them.
// Owns: the three kinds of declaration every command uses (a value flag, a switch, a
// positional; each flag is declared once, with its help text, and --help is generated from
// the declarations), the help layout (the command's usage and description first, then its
// flags by group), and turning CLI11's parse errors into the one-line Error that names the
// flag (main.cpp prints it). Which command declares which flag: the cmd_*.cpp files, and the
// render flags that render, animate, study and bench share in render_flags.h.
#pragma once
#include <string>
#include <vector>

#include "cli/args.h"

namespace CLI {
class App;
class Option;
class ParseError;
}  // namespace CLI

namespace vdbsplat::cli {

using Argv = std::vector<std::string>;

/// @brief Declares value flag @p name ("--size", "-o") shown as `name VALUE` with @p help.
/// Repeats are kept for Args, which refuses them by name.
CLI::Option* addValueFlag(CLI::App& app, const std::string& name, const std::string& value, const std::string& help);

/// @brief Declares switch @p name ("-v", "--resume"): a flag without a value.
CLI::Option* addSwitch(CLI::App& app, const std::string& name, const std::string& help);

/// @brief Declares the positional @p name ("FILE.vdb"); @p many: any number of them, else at
/// most one. Never required here: each command says what is missing in its own words.
CLI::Option* addPositional(CLI::App& app, const std::string& name, const std::string& help, bool many = false);

/// @brief Makes @p app print help in vdbsplat's layout: its description (a one-line summary,
/// which is also the command's line in `vdbsplat --help`, then the usage line and the details)
/// and then its flags by group. Subcommands added later inherit it.
void useHelpLayout(CLI::App& app);

/// @brief The one-line message for CLI11's parse error @p e of @p top (the app parse() was
/// called on): it names the unknown option, the flag missing its value, or the unknown command.
std::string parseErrorMessage(const CLI::App& top, const CLI::ParseError& e);

/// @brief Parses @p words (the command line without the program name) with @p app: app.parse
/// with "--flag=" read as the empty value it is. @throw CLI::ParseError as app.parse does.
void parseWords(CLI::App& app, const Argv& words);

/// @brief Parses @p argv (the arguments after the command name) with @p app, a command
/// declared on its own (not a subcommand). @throw Error with parseErrorMessage for a bad
/// command line, and Error "--help: not here" when it asks for help.
Args parseAlone(CLI::App& app, const Argv& argv);

}  // namespace vdbsplat::cli
