// study/spec.cpp — study files to study arguments (see spec.h).
#include "study/spec.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat::study {

namespace {

enum class Kind { Paths, Words, Numbers, Number, Integer, Word, Size };

/// Every key a study file may hold: its flag and the JSON it takes.
const std::map<std::string, std::pair<const char*, Kind>>& keys() {
    static const std::map<std::string, std::pair<const char*, Kind>> k{
        {"volumes", {"", Kind::Paths}},         {"modes", {"--modes", Kind::Words}},
        {"kernels", {"--kernels", Kind::Words}}, {"views", {"--views", Kind::Words}},
        {"distances", {"--distances", Kind::Numbers}}, {"base", {"--base", Kind::Number}},
        {"size", {"--size", Kind::Size}},        {"spp", {"--spp", Kind::Integer}},
        {"tf", {"--tf", Kind::Word}},            {"tfs", {"--tfs", Kind::Words}},            {"grid", {"--grid", Kind::Word}},
        {"threshold", {"--threshold", Kind::Number}}, {"lod", {"--lod", Kind::Number}},
        {"fov", {"--fov", Kind::Number}},        {"footprint", {"--footprint", Kind::Word}},
        {"filter_order", {"--filter-order", Kind::Word}}, {"subpixels", {"--subpixels", Kind::Integer}}};
    return k;
}

std::string keyList() {
    std::string s;
    for (const auto& [k, v] : keys()) s += (s.empty() ? "" : ", ") + k;
    return s;
}

std::string numberText(const nlohmann::json& v, const std::string& at) {
    if (!v.is_number()) throw Error(at + ": expected a number, got " + std::string(v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw Error(at + ": expected a finite number");
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", d);
    return buf;
}

std::string integerText(const nlohmann::json& v, const std::string& at) {
    if (!v.is_number_integer()) throw Error(at + ": expected an integer, got " + std::string(v.type_name()));
    return v.is_number_unsigned() ? std::to_string(v.get<unsigned long long>()) : std::to_string(v.get<long long>());
}

std::string wordText(const nlohmann::json& v, const std::string& at, bool inList) {
    if (!v.is_string()) throw Error(at + ": expected a string, got " + std::string(v.type_name()));
    const std::string s = v.get<std::string>();
    if (s.empty()) throw Error(at + ": empty string");
    if (inList && s.find(',') != std::string::npos) throw Error(at + ": '" + printable(s) + "' holds a comma");
    if (s.find('\0') != std::string::npos) throw Error(at + ": holds a NUL character");
    return s;
}

const nlohmann::json& nonEmptyArray(const nlohmann::json& v, const std::string& at) {
    if (!v.is_array()) throw Error(at + ": expected an array, got " + std::string(v.type_name()));
    if (v.empty()) throw Error(at + ": empty list");
    return v;
}

SpecArgument argumentFor(const std::string& key, Kind kind, const char* flag, const nlohmann::json& v,
                         const std::string& at) {
    SpecArgument a{key, {}};
    auto joined = [&](auto item) {
        std::string s;
        const auto& list = nonEmptyArray(v, at);
        for (size_t i = 0; i < list.size(); ++i) s += (i ? "," : "") + item(list[i], at + "[" + std::to_string(i) + "]");
        return s;
    };
    switch (kind) {
        case Kind::Paths:
            for (size_t i = 0; i < nonEmptyArray(v, at).size(); ++i)
                a.args.push_back(wordText(v[i], at + "[" + std::to_string(i) + "]", false));
            return a;
        case Kind::Words:
            a.args = {flag, joined([](const nlohmann::json& x, const std::string& w) { return wordText(x, w, true); })};
            return a;
        case Kind::Numbers:
            a.args = {flag, joined([](const nlohmann::json& x, const std::string& w) { return numberText(x, w); })};
            return a;
        case Kind::Number: a.args = {flag, numberText(v, at)}; return a;
        case Kind::Integer: a.args = {flag, integerText(v, at)}; return a;
        case Kind::Word: a.args = {flag, wordText(v, at, false)}; return a;
        case Kind::Size:
            if (!v.is_array() || v.size() != 2) throw Error(at + ": expected [width, height]");
            a.args = {flag, integerText(v[0], at + "[0]") + "x" + integerText(v[1], at + "[1]")};
            return a;
    }
    return a;
}

}  // namespace

std::vector<SpecArgument> parseSpec(const std::string& text, const std::string& name) {
    if (text.size() > kMaxSpecBytes)
        throw Error(name + ": larger than " + std::to_string(kMaxSpecBytes >> 20) + " MB, not a study file");
    if (jsonNestingPastLimit(text, kMaxSpecNesting) != std::string::npos)
        throw Error(name + ": JSON nested deeper than " + std::to_string(kMaxSpecNesting) + " levels (expected {\"volumes\": [...], ...})");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        std::string what = e.what();
        if (const size_t p = what.find("] "); p != std::string::npos) what = what.substr(p + 2);
        throw Error(name + ": not valid JSON: " + what);
    }
    if (!j.is_object()) throw Error(name + ": expected a JSON object, got " + std::string(j.type_name()));
    std::vector<SpecArgument> out;
    for (const auto& item : j.items()) {
        const auto it = keys().find(item.key());
        if (it == keys().end())
            throw Error(name + ": unknown key '" + printable(item.key()) + "' (expected " + keyList() + ")");
        out.push_back(argumentFor(item.key(), it->second.second, it->second.first, item.value(), name + ": " + item.key()));
    }
    if (!j.contains("volumes")) throw Error(name + ": volumes: missing (a list of .vdb files)");
    return out;
}

std::vector<SpecArgument> loadSpec(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": no such study file");
    if (std::filesystem::file_size(path, ec) > kMaxSpecBytes)
        throw Error(path + ": larger than " + std::to_string(kMaxSpecBytes >> 20) + " MB, not a study file");
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    if (!in && !in.eof()) throw Error(path + ": cannot be read");
    return parseSpec(s.str(), path);
}

}  // namespace vdbsplat::study
