// util/parse.h — strict parsing of numbers and number lists from text.
// Owns: the conversions every flag and file format uses, so "1.5x", "nan" or
// "1,2" where three values are needed are rejected the same way everywhere.
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace vdbsplat {

/// @brief Parses a finite double; the whole string must be consumed.
/// @throw Error "<what>: expected a number, got '<text>'".
double parseDouble(std::string_view text, const std::string& what);

/// @brief Parses a base-10 integer in [lo, hi]; the whole string must be consumed.
/// @throw Error naming @p what when malformed or out of range.
long long parseInt(std::string_view text, const std::string& what,
                   long long lo, long long hi);

/// @brief Parses exactly @p count finite doubles separated by commas ("1,2,3").
/// @throw Error naming @p what when the count or any number is wrong.
std::vector<double> parseDoubleList(std::string_view text, const std::string& what, size_t count);

/// @brief Parses "WxH" (e.g. "400x400") with each side in [1, maxSide].
/// @throw Error naming @p what when malformed or out of range.
void parseSize(std::string_view text, const std::string& what, int maxSide, int& width, int& height);

/// @brief Splits "a,b,c" into items trimmed of spaces and tabs.
/// @throw Error "<flag>: empty item in '<text>' …" for an empty list or an empty item.
std::vector<std::string> splitList(const std::string& text, const std::string& flag);

/// @brief The byte offset at which JSON @p text first nests deeper than @p limit levels of [ and {
/// (brackets inside strings do not count), or std::string::npos. Checked before parsing: a file
/// of 100 000 '[' would otherwise exhaust the stack of a recursive parser.
size_t jsonNestingPastLimit(std::string_view text, int limit);

/// @brief @p text for an error message: bytes other than printable ASCII become '?' (a file's
/// header cannot send terminal escapes), cut to @p maxChars with "..." after.
std::string printable(std::string_view text, size_t maxChars = 60);

}  // namespace vdbsplat
