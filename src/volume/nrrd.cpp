// volume/nrrd.cpp — the NRRD reader (see nrrd.h), following the header forms of Teem's NRRD
// format definition (NRRD0001..NRRD0005 magic, "field: value" lines, "key:=value" pairs,
// '#' comments, a blank line before attached data).
// Owns: the header's line reader (bounded), the per-field parsers and the consistency checks
// between fields; the voxels themselves are read by readVoxels (volume/raw.h).
#include "volume/nrrd.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "util/error.h"
#include "util/parse.h"
#include "volume/index_map.h"

namespace vdbsplat {

namespace {

/// The header as lines of fields; `end` is the file offset of the first data byte (attached).
struct NrrdFields {
    std::map<std::string, std::string> fields;
    uint64_t end = 0;
    bool attached = false;  ///< a blank line ended the header (data may follow)
};

/// Fields that are read and ignored (they do not change the voxels or their placement).
const std::set<std::string> kIgnoredFields = {
    "content",      "kinds",        "centers",      "centerings", "labels",     "units",     "space units",
    "measurement frame", "min",     "max",          "old min",    "oldmin",     "old max",   "oldmax",
    "sample units", "sampleunits",  "thicknesses",  "axis mins",  "axismins",   "axis maxs", "axismaxs",
    "number",       "block size",   "blocksize"};

/// Field spellings Teem accepts for the same field, mapped to one name.
std::string canonical(const std::string& name) {
    static const std::map<std::string, std::string> alias = {
        {"datafile", "data file"}, {"byteskip", "byte skip"}, {"lineskip", "line skip"}};
    const auto it = alias.find(name);
    return it == alias.end() ? name : it->second;
}

std::string trimmed(std::string_view s) {
    const size_t a = s.find_first_not_of(" \t\r");
    if (a == s.npos) return "";
    return std::string(s.substr(a, s.find_last_not_of(" \t\r") - a + 1));
}

std::vector<std::string> words(const std::string& s) {
    std::istringstream in(s);
    std::vector<std::string> out;
    for (std::string w; in >> w && out.size() < 64;) out.push_back(w);
    return out;
}

void checkMagic(const std::string& path, const std::string& line) {
    if (line.size() != 8 || line.compare(0, 7, "NRRD000") != 0 || line[7] < '1' || line[7] > '5')
        throw Error(path + ": not a NRRD file (the first line must be NRRD0001..NRRD0005, got '" + printable(line) +
                    "')");
}

/// Reads one line (without its '\n') of at most @p limit bytes; false at the end of the file.
bool boundedLine(std::istream& in, std::string& line, uint64_t limit, uint64_t& used) {
    line.clear();
    int c = 0;
    while ((c = in.get()) != EOF && c != '\n') {
        if (++used > limit) return true;
        line += char(c);
    }
    if (c == '\n') ++used;
    return c == '\n' || !line.empty();
}

/// Reads the header lines of @p path (at most kMaxNrrdHeaderBytes).
NrrdFields readFields(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open");
    NrrdFields out;
    std::string line;
    uint64_t used = 0;
    for (int n = 0; boundedLine(in, line, kMaxNrrdHeaderBytes, used); ++n) {
        if (used > kMaxNrrdHeaderBytes)
            throw Error(path + ": header is longer than " + std::to_string(kMaxNrrdHeaderBytes) + " bytes (no blank line ends it)");
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (n == 0) {
            checkMagic(path, line);
            continue;
        }
        if (line.empty()) {
            out.attached = true;
            break;
        }
        if (line[0] == '#' || line.find(":=") != line.npos) continue;  // comment, key/value pair
        const size_t colon = line.find(": ");
        if (colon == line.npos)
            throw Error(path + ": header line " + std::to_string(n + 1) + " is not 'field: value' ('" +
                        printable(line) + "')");
        const std::string name = canonical(line.substr(0, colon));
        if (out.fields.count(name)) throw Error(path + ": " + printable(name) + ": given twice");
        out.fields[name] = trimmed(std::string_view(line).substr(colon + 2));
    }
    if (in.bad()) throw Error(path + ": cannot read the header");
    out.end = used;
    return out;
}

/// Reads NRRD's data from the fields; every error names the path and the field.
class HeaderParser {
public:
    HeaderParser(const std::string& path, NrrdFields fields) : path_(path), f_(std::move(fields)) {}

    NrrdHeader parse(uint64_t maxVoxels) {
        for (const auto& [name, value] : f_.fields)
            if (!known(name)) throw Error(at(name) + ": unknown field");
        NrrdHeader h;
        if (parseInt(need("dimension"), at("dimension"), 1, 16) != 3)
            throw Error(at("dimension") + ": only 3-dimensional volumes are supported, got " + need("dimension"));
        h.layout.type = type();
        h.layout.dims = sizes();
        checkVoxelLimit(h.layout.dims, maxVoxels, at("sizes"));
        h.layout.bigEndian = bigEndian(h.layout.type);
        h.source = source();
        geometry(h);
        return h;
    }

private:
    static bool known(const std::string& name) {
        static const std::set<std::string> used = {"dimension", "type",  "sizes", "endian", "encoding",
                                                   "data file", "byte skip", "line skip", "space",
                                                   "space dimension", "space directions", "spacings", "space origin"};
        return used.count(name) || kIgnoredFields.count(name);
    }
    std::string at(const std::string& field) const { return path_ + ": " + printable(field); }
    const std::string* get(const std::string& field) const {
        const auto it = f_.fields.find(field);
        return it == f_.fields.end() ? nullptr : &it->second;
    }
    const std::string& need(const std::string& field) const {
        if (const std::string* v = get(field)) return *v;
        throw Error(at(field) + ": missing (a NRRD header must give it)");
    }

    RawType type() const {
        static const std::map<std::string, RawType> types = {
            {"uchar", RawType::UInt8},           {"unsigned char", RawType::UInt8},   {"uint8", RawType::UInt8},
            {"uint8_t", RawType::UInt8},         {"short", RawType::Int16},           {"short int", RawType::Int16},
            {"signed short", RawType::Int16},    {"signed short int", RawType::Int16}, {"int16", RawType::Int16},
            {"int16_t", RawType::Int16},         {"ushort", RawType::UInt16},         {"unsigned short", RawType::UInt16},
            {"unsigned short int", RawType::UInt16}, {"uint16", RawType::UInt16},     {"uint16_t", RawType::UInt16},
            {"float", RawType::Float32},         {"double", RawType::Float64}};
        const std::string& t = need("type");
        const auto it = types.find(t);
        if (it == types.end())
            throw Error(at("type") + ": unsupported type '" + printable(t) +
                        "' (supported: uchar/uint8, short/int16, ushort/uint16, float, double)");
        return it->second;
    }

    std::array<int, 3> sizes() const {
        const std::vector<std::string> w = words(need("sizes"));
        if (w.size() != 3) throw Error(at("sizes") + ": expected 3 sizes (dimension 3), got '" + printable(need("sizes")) + "'");
        std::array<int, 3> dims{};
        for (int a = 0; a < 3; ++a) dims[a] = int(parseInt(w[a], at("sizes"), 1, kMaxRawDim));
        return dims;
    }

    bool bigEndian(RawType type) const {
        const std::string* e = get("endian");
        if (!e) {
            if (rawTypeSize(type) > 1) throw Error(at("endian") + ": missing (needed for types wider than one byte)");
            return false;
        }
        if (*e != "little" && *e != "big") throw Error(at("endian") + ": expected little or big, got '" + printable(*e) + "'");
        return *e == "big";
    }

    VoxelSource source() const {
        VoxelSource s;
        s.sizeField = "sizes";
        const std::string& enc = need("encoding");
        if (enc == "raw") {
            s.encoding = VoxelSource::Encoding::Raw;
        } else if (enc == "gzip" || enc == "gz") {
            s.encoding = VoxelSource::Encoding::Gzip;
        } else {
            throw Error(at("encoding") + ": unsupported encoding '" + printable(enc) + "' (supported: raw, gzip)");
        }
        if (const std::string* skip = get("line skip"); skip && parseInt(*skip, at("line skip"), 0, 1LL << 40) != 0)
            throw Error(at("line skip") + ": only 0 is supported (use byte skip)");
        if (const std::string* skip = get("byte skip")) {
            const long long b = parseInt(*skip, at("byte skip"), -1, 1LL << 40);
            if (b == -1 && s.encoding != VoxelSource::Encoding::Raw)
                throw Error(at("byte skip") + ": -1 (data at the end) needs encoding raw");
            s.atEnd = b == -1;
            s.skip = b < 0 ? 0 : uint64_t(b);
        }
        dataFile(s);
        return s;
    }

    void dataFile(VoxelSource& s) const {
        const std::string* file = get("data file");
        if (!file) {
            if (!f_.attached) throw Error(at("data file") + ": missing, and no blank line before attached data");
            s.path = s.label = path_;
            s.offset = f_.end;
            return;
        }
        if (file->empty() || file->find(' ') != file->npos || *file == "LIST")
            throw Error(at("data file") + ": only one data file is supported, got '" + printable(*file) + "'");
        const std::filesystem::path p(*file);
        s.path = p.is_absolute() ? p.string() : (std::filesystem::path(path_).parent_path() / p).string();
        s.label = path_ + ": data file " + s.path;
    }

    int spaceDimension() const {
        const std::string* space = get("space");
        const std::string* dim = get("space dimension");
        if (space && dim) throw Error(at("space dimension") + ": given together with space (give one)");
        if (dim) return int(parseInt(*dim, at("space dimension"), 1, 16));
        if (!space) return 0;
        static const std::set<std::string> three = {
            "right-anterior-superior", "RAS", "left-anterior-superior", "LAS", "left-posterior-superior", "LPS",
            "scanner-xyz", "3D-right-handed", "3D-left-handed"};
        if (!three.count(*space)) throw Error(at("space") + ": unsupported space '" + printable(*space) + "' (needs 3 spatial axes)");
        return 3;
    }

    /// "(x,y,z)" → vector, the field named in errors.
    openvdb::Vec3d vector(const std::string& text, const std::string& field) const {
        if (text.size() < 2 || text.front() != '(' || text.back() != ')')
            throw Error(at(field) + ": expected a vector (x,y,z), got '" + printable(text) + "'");
        const std::vector<double> v = parseDoubleList(std::string_view(text).substr(1, text.size() - 2), at(field), 3);
        return {v[0], v[1], v[2]};
    }

    void geometry(NrrdHeader& h) const {
        const int space = spaceDimension();
        const std::string* dirs = get("space directions");
        const std::string* spacings = get("spacings");
        const std::string* origin = get("space origin");
        if (space != 0 && space != 3) throw Error(at("space dimension") + ": must be 3, got " + std::to_string(space));
        if ((dirs || origin) && space == 0) throw Error(at(dirs ? "space directions" : "space origin") + ": needs a space or space dimension field");
        if (dirs && spacings) throw Error(at("spacings") + ": given together with space directions (give one)");
        if (space == 3 && !dirs) throw Error(at("space directions") + ": missing (a header with a space must give them)");
        for (int a = 0; a < 3; ++a) h.axes[a] = openvdb::Vec3d(0.0), h.axes[a][a] = 1.0;
        if (dirs) {
            const std::vector<std::string> w = words(*dirs);
            if (w.size() != 3) throw Error(at("space directions") + ": expected 3 vectors, got '" + printable(*dirs) + "'");
            for (int a = 0; a < 3; ++a) h.axes[a] = vector(w[a], "space directions");
        } else if (spacings) {
            const std::vector<std::string> w = words(*spacings);
            if (w.size() != 3) throw Error(at("spacings") + ": expected 3 numbers, got '" + printable(*spacings) + "'");
            for (int a = 0; a < 3; ++a) h.axes[a][a] = parseDouble(w[a], at("spacings"));
        }
        if (origin) h.origin = vector(*origin, "space origin");
        h.transform = indexToWorld(h.axes, h.origin, at(dirs ? "space directions" : "spacings"), at("space origin"));
    }

    std::string path_;
    NrrdFields f_;
};

}  // namespace

NrrdHeader readNrrdHeader(const std::string& path, uint64_t maxVoxels) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(path + ": no such file");
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": not a regular file");
    return HeaderParser(path, readFields(path)).parse(maxVoxels);
}

openvdb::FloatGrid::Ptr convertNrrd(const std::string& path, const ConvertOptions& options, RawStats* stats) {
    const NrrdHeader h = readNrrdHeader(path, options.maxVoxels);
    return readVoxels(h.source, h.layout, options.threshold, h.transform, stats);
}

}  // namespace vdbsplat
