// util/parse.cpp — strict number parsing (see parse.h).
#include "util/parse.h"

#include <charconv>
#include <cmath>

#include "util/error.h"

namespace vdbsplat {

namespace {
std::string quoted(std::string_view text) { return "'" + printable(text) + "'"; }
std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}
}  // namespace

double parseDouble(std::string_view text, const std::string& what) {
    const std::string_view t = trim(text);
    double value = 0.0;
    const char* first = t.data();
    const char* last = t.data() + t.size();
    if (!t.empty() && *first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (t.empty() || ec != std::errc() || ptr != last)
        throw Error(what + ": expected a number, got " + quoted(text));
    if (!std::isfinite(value)) throw Error(what + ": expected a finite number, got " + quoted(text));
    return value;
}

long long parseInt(std::string_view text, const std::string& what, long long lo, long long hi) {
    const std::string_view t = trim(text);
    long long value = 0;
    const char* first = t.data();
    const char* last = t.data() + t.size();
    if (!t.empty() && *first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (t.empty() || ec == std::errc::result_out_of_range || (ec == std::errc() && ptr == last && (value < lo || value > hi)))
        throw Error(what + ": expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                    "], got " + quoted(text));
    if (ec != std::errc() || ptr != last) throw Error(what + ": expected an integer, got " + quoted(text));
    return value;
}

std::vector<double> parseDoubleList(std::string_view text, const std::string& what, size_t count) {
    std::vector<double> values;
    size_t start = 0;
    while (true) {
        const size_t comma = text.find(',', start);
        const std::string_view item = text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
        values.push_back(parseDouble(item, what));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    if (values.size() != count)
        throw Error(what + ": expected " + std::to_string(count) + " comma-separated numbers, got " + quoted(text));
    return values;
}

void parseSize(std::string_view text, const std::string& what, int maxSide, int& width, int& height) {
    const size_t x = text.find_first_of("xX");
    if (x == std::string_view::npos) throw Error(what + ": expected WxH (e.g. 400x400), got " + quoted(text));
    width = static_cast<int>(parseInt(text.substr(0, x), what + " width", 1, maxSide));
    height = static_cast<int>(parseInt(text.substr(x + 1), what + " height", 1, maxSide));
}

std::vector<std::string> splitList(const std::string& text, const std::string& flag) {
    std::vector<std::string> items;
    size_t start = 0;
    while (true) {
        const size_t comma = text.find(',', start);
        std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        const size_t b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
        item = b == std::string::npos ? "" : item.substr(b, e - b + 1);
        if (item.empty()) throw Error(flag + ": empty item in '" + text + "' (expected a comma-separated list)");
        items.push_back(item);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return items;
}

size_t jsonNestingPastLimit(std::string_view text, int limit) {
    int depth = 0;
    bool inString = false, escaped = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > limit) return i;
        } else if (c == ']' || c == '}') {
            depth = depth > 0 ? depth - 1 : 0;
        }
    }
    return std::string::npos;
}

std::string printable(std::string_view text, size_t maxChars) {
    std::string out;
    for (char c : text.substr(0, maxChars)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
    return text.size() > maxChars ? out + "..." : out;
}

}  // namespace vdbsplat
