// volume/vdb_reader.cpp — reading a .vdb grid in process (see vdb_reader.h).
// The layout, as OpenVDB 10 writes and reads it (io/Archive.cc, io/GridDescriptor.cc,
// tree/RootNode.h, InternalNode.h, LeafNode.h readTopology/readBuffers, io/Compression.h
// readCompressedValues), all little-endian:
//   file: int64 magic, uint32 file version, uint32 library major, minor, char hasGridOffsets,
//     36-char UUID, metadata, int32 grid count, per grid a descriptor: name, type (suffix
//     "_HalfFloat": values stored as half), instance parent (strings: uint32 length + bytes),
//     int64 gridPos, blockPos, endPos.
//   grid at gridPos: uint32 compression flags, metadata, map type name + map, then the
//     topology: int32 buffer count (1), root background, uint32 tile and child counts, tiles
//     (int32[3] origin, value, bool active), children (int32[3] origin, upper node); an
//     internal node is child mask, value mask, its NUM_VALUES tile values (compressed, below),
//     then its children in mask order; a leaf is its value mask. From blockPos, the leaves'
//     buffers in the same order: value mask again (io::File seeks over it: the topology's
//     counts), then 512 values (compressed).
//   compressed values: int8 mode (NO_MASK_OR_INACTIVE_VALS … NO_MASK_AND_ALL_VALS), up to two
//     inactive values (full value type), a selection mask (modes 3-5), then a chunk of the
//     active values only (mask compression on, mode not 6) or of all; a chunk is int64 n and
//     n compressed bytes (blosc or zlib), or -n and n raw bytes; uncompressed grids: raw.
#include "volume/vdb_reader.h"

#include <openvdb/io/Compression.h>
#include <openvdb/io/io.h>
#include <openvdb/math/Maps.h>

#include <blosc.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <istream>
#include <limits>
#include <functional>
#include <memory>
#include <mutex>
#include <streambuf>
#include <string_view>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "util/error.h"
#include "volume/grid.h"
#include "volume/leaf_values.h"
#include "volume/vdb_check.h"
#include "volume/vdb_types.h"

namespace vdbsplat {

namespace {

using FloatTree = openvdb::FloatTree;
using Root = FloatTree::RootNodeType;
using Upper = Root::ChildNodeType;
using Lower = Upper::ChildNodeType;
using Leaf = Lower::ChildNodeType;
using openvdb::Coord;

constexpr int64_t kVdbMagic = 0x56444220;
constexpr uint32_t kFirstVersion = 222;  ///< OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION: the layout read here
constexpr uint32_t kLastVersion = openvdb::OPENVDB_FILE_VERSION;
constexpr uint64_t kMaxStringBytes = 1 << 16;  ///< longer grid names or type names are left to OpenVDB
constexpr uint64_t kLeafGrain = 64;            ///< leaves per parallel task
/// Leaves located, then read in parallel, per batch; the file's bytes behind a batch are
/// released before the next (so the mapped file and the tree are never both whole in memory).
constexpr size_t kLeafBatch = 4096;
constexpr uint64_t kPrefetchBytes = 8 << 20;   ///< bytes prefaulted ahead of each batch

/// Thrown where this reader leaves the file to OpenVDB.
struct Unsupported {
    const char* why;
};

/// The file's bytes and its name for messages.
struct Image {
    const char* data;
    uint64_t size;
    const std::string& label;
    /// Says that bytes [begin, end) are about to be read (a mapped file prefaults them) and
    /// that bytes before @p end are no longer needed (it drops them from this process); no-ops when empty.
    std::function<void(uint64_t, uint64_t)> willNeed = {}, release = {};
};

/// Bounds-checked reads from [pos, end) of an Image.
class Cursor {
public:
    Cursor(const Image& f, uint64_t pos, uint64_t end) : f_(&f), pos_(pos), end_(std::min(end, f.size)) {
        if (pos_ > end_) corrupt("section offset");
    }
    const char* take(uint64_t n, const char* what) {
        if (n > end_ - pos_) corrupt(what);
        const char* p = f_->data + pos_;
        pos_ += n;
        return p;
    }
    template <typename T>
    T get(const char* what) {
        T v;
        std::memcpy(&v, take(sizeof(T), what), sizeof(T));
        return v;
    }
    /// A string (uint32 length + bytes); longer than kMaxStringBytes: Unsupported.
    std::string string(const char* what) {
        const uint32_t n = get<uint32_t>(what);
        if (n > kMaxStringBytes) throw Unsupported{"a long name string"};
        const char* p = take(n, what);
        return std::string(p, n);
    }
    void seek(uint64_t to, const char* what) {
        if (to < pos_ || to > end_) corrupt(what);
        pos_ = to;
    }
    uint64_t pos() const { return pos_; }
    const char* here() const { return f_->data + pos_; }
    uint64_t left() const { return end_ - pos_; }
    [[noreturn]] void corrupt(const std::string& what) const {
        throw Error(f_->label + ": truncated or corrupt VDB file (" + what + " at byte " + std::to_string(pos_) +
                    " of " + std::to_string(f_->size) + ")");
    }

private:
    const Image* f_;
    uint64_t pos_, end_;
};

// ---- file header, metadata, descriptors ----------------------------------------------------

/// Walks a metadata block as OpenVDB's MetaMap::readMeta reads it (a registered fixed-size
/// type reads its own size, fixedMetadataBytes: it must declare that size, as checkVdbStructure
/// requires), calling @p item(name, type, value) for every item.
template <class Item>
void walkMetadata(Cursor& c, Item&& item) {
    const int32_t count = c.get<int32_t>("metadata count");
    if (count < 0 || uint64_t(count) > c.left() / 12) c.corrupt("metadata count");
    for (int32_t i = 0; i < count; ++i) {
        const uint32_t nameBytes = c.get<uint32_t>("metadata name");
        const std::string_view name(c.take(nameBytes, "metadata name"), nameBytes);
        const std::string type = c.string("metadata type");
        const uint32_t declared = c.get<uint32_t>("metadata value size");
        const std::optional<uint64_t> fixed = fixedMetadataBytes(type);
        if (fixed && *fixed != declared) c.corrupt("metadata value size");
        item(name, type, std::string_view(c.take(declared, "metadata value"), declared));
    }
}

void skipMetadata(Cursor& c) {
    walkMetadata(c, [](std::string_view, const std::string&, std::string_view) {});
}

struct Descriptor {
    std::string name, type;  ///< type without "_HalfFloat"
    bool half = false;
    int64_t gridPos = 0, blockPos = 0, endPos = 0;
};

/// Header, file metadata and grid descriptors; Unsupported for layouts left to OpenVDB.
std::vector<Descriptor> readDescriptors(const Image& f) {
    Cursor c(f, 0, f.size);
    if (c.get<int64_t>("magic number") != kVdbMagic) throw Unsupported{"not a VDB file"};
    const uint32_t version = c.get<uint32_t>("file version");
    if (version < kFirstVersion || version > kLastVersion) throw Unsupported{"a file version before 222 or after 224"};
    c.get<uint32_t>("library major version");
    c.get<uint32_t>("library minor version");
    if (!c.get<char>("grid offsets flag")) throw Unsupported{"a file without grid offsets (io::Stream)"};
    c.take(36, "file UUID");
    skipMetadata(c);
    const int32_t count = c.get<int32_t>("grid count");
    if (count < 0 || uint64_t(count) > c.left() / 36) c.corrupt("grid count");
    std::vector<Descriptor> out(static_cast<size_t>(count));
    for (Descriptor& d : out) {
        d.name = c.string("grid name");
        d.type = c.string("grid type");
        if (!c.string("grid instance parent").empty()) throw Unsupported{"an instanced grid"};
        d.gridPos = c.get<int64_t>("grid offset");
        d.blockPos = c.get<int64_t>("grid data offset");
        d.endPos = c.get<int64_t>("grid end offset");
        if (d.gridPos < int64_t(c.pos()) || d.blockPos < d.gridPos || d.endPos < d.blockPos ||
            uint64_t(d.endPos) > f.size)
            c.corrupt("grid extends past the end of the file");
        // Names made unique by OpenVDB (a suffix after \x1e) or empty: its lookup rules apply.
        if (d.name.empty() || d.name.find('\x1e') != std::string::npos) throw Unsupported{"a suffixed grid name"};
        static const std::string kHalf = "_HalfFloat";
        if (d.type.size() > kHalf.size() && d.type.compare(d.type.size() - kHalf.size(), kHalf.size(), kHalf) == 0) {
            d.type.resize(d.type.size() - kHalf.size());
            d.half = true;
        }
        if (!isRegisteredGridType(d.type)) throw Unsupported{"an unregistered grid type"};
        c.seek(uint64_t(d.endPos), "grid end offset");  // OpenVDB reads the next descriptor there
    }
    return out;
}

bool isFloat(const std::string& type) { return type == FloatTree::treeType(); }
bool isDouble(const std::string& type) { return type == openvdb::DoubleTree::treeType(); }

/// The descriptor loadVolume reads (readGridToRender's choice); Unsupported when there is none
/// (OpenVDB's path words that error).
const Descriptor& chooseGrid(const std::vector<Descriptor>& all, const std::string& gridName) {
    std::vector<std::string> names;
    std::vector<bool> scalar;
    for (const Descriptor& d : all) names.push_back(d.name), scalar.push_back(isFloat(d.type) || isDouble(d.type));
    const size_t k = gridName.empty() ? defaultGridIndex(names, scalar)
                                      : size_t(std::find(names.begin(), names.end(), gridName) - names.begin());
    if (k >= all.size() || !scalar[k]) throw Unsupported{"no such float or double grid"};
    return all[k];
}

// ---- compressed values ---------------------------------------------------------------------

/// How a grid's values are stored, and its background, as readCompressedValues needs them.
template <typename V>
struct Codec {
    uint32_t compression = 0;  ///< io::COMPRESS_ZIP | COMPRESS_ACTIVE_MASK | COMPRESS_BLOSC
    bool half = false;         ///< values stored as 16-bit floats
    V background{};
};

/// Checks a blosc chunk's header against its @p n bytes and the @p bytes it must hold.
void checkBlosc(Cursor& c, const char* src, uint64_t n, uint64_t bytes) {
    size_t nbytes = 0, cbytes = 0, block = 0;
    if (n < BLOSC_MIN_HEADER_LENGTH || blosc_cbuffer_validate(src, size_t(n), &nbytes) != 0)
        c.corrupt("invalid blosc chunk");
    blosc_cbuffer_sizes(src, &nbytes, &cbytes, &block);
    if (nbytes != bytes || cbytes != n)
        c.corrupt("blosc chunk of " + std::to_string(n) + " bytes whose header says " + std::to_string(cbytes) +
                  " bytes holding " + std::to_string(nbytes) + ", not " + std::to_string(bytes));
}

void decodeBlosc(Cursor& c, const char* src, char* dest, uint64_t bytes) {
    if (bytes > 0 && blosc_decompress_ctx(src, dest, bytes, /*numinternalthreads=*/1) != int(bytes))
        c.corrupt("blosc chunk that does not decompress");
}

/// Inflates exactly @p n bytes into exactly @p bytes bytes (OpenVDB writes one zlib stream per chunk).
void decodeZlib(Cursor& c, const char* src, uint64_t n, char* dest, uint64_t bytes) {
    char unused;
    uLongf out = uLongf(bytes);
    uLong in = uLong(n);
    const int status = uncompress2(reinterpret_cast<Bytef*>(bytes ? dest : &unused), &out,
                                   reinterpret_cast<const Bytef*>(src), &in);
    if (status != Z_OK || out != bytes || in != n)
        c.corrupt("zlib chunk of " + std::to_string(n) + " bytes that does not inflate to exactly " +
                  std::to_string(bytes) + " bytes");
}

/// One chunk of @p bytes bytes (after decompression) into @p dest, or skipped when it is null.
void readChunk(Cursor& c, char* dest, uint64_t bytes, uint32_t compression) {
    const bool blosc = compression & openvdb::io::COMPRESS_BLOSC;
    if (!blosc && !(compression & openvdb::io::COMPRESS_ZIP)) {
        const char* src = c.take(bytes, "uncompressed values");
        if (dest) std::memcpy(dest, src, bytes);
        return;
    }
    const int64_t n = c.get<int64_t>(blosc ? "blosc chunk size" : "zlib chunk size");
    if (n <= 0) {  // stored raw
        if (uint64_t(0) - uint64_t(n) != bytes) c.corrupt("raw chunk size");
        const char* src = c.take(bytes, "raw chunk");
        if (dest) std::memcpy(dest, src, bytes);
        return;
    }
    const char* src = c.take(uint64_t(n), blosc ? "blosc chunk" : "zlib chunk");
    if (blosc) checkBlosc(c, src, uint64_t(n), bytes);  // while skipping too: errors are found in file order
    if (!dest) return;
    if (blosc)
        decodeBlosc(c, src, dest, bytes);
    else
        decodeZlib(c, src, uint64_t(n), dest, bytes);
}

/// Scratch arrays for one thread's reads (mask-compressed values, half floats).
template <typename V>
struct Scratch {
    std::vector<V> values;
    std::vector<uint16_t> halves;
};

/// @p count stored values into @p out (skipped when null), widening half floats.
template <typename V>
void readStored(Cursor& c, V* out, uint32_t count, const Codec<V>& codec, Scratch<V>& s) {
    if (!codec.half) {
        readChunk(c, reinterpret_cast<char*>(out), uint64_t(count) * sizeof(V), codec.compression);
        return;
    }
    if (count == 0) return;  // OpenVDB's HalfReader reads nothing then, not even a chunk header
    if (!out) return readChunk(c, nullptr, uint64_t(count) * 2, codec.compression);
    s.halves.resize(count);
    readChunk(c, reinterpret_cast<char*>(s.halves.data()), uint64_t(count) * 2, codec.compression);
    for (uint32_t i = 0; i < count; ++i) {
        openvdb::math::half h;
        h.setBits(s.halves[i]);
        out[i] = V(float(h));
    }
}

/// Spreads the active values @p active over @p out (in mask order); inactive ones are
/// @p inactive1 where @p selection is on, else @p inactive0 (readCompressedValues' rule).
/// Word by word and without branches per voxel: sparse leaves' masks are unpredictable.
template <typename V, typename MaskT>
void expandActive(V* out, const V* active, const MaskT& valueMask, const MaskT& selection, V inactive0, V inactive1) {
    using Word = typename MaskT::Word;
    for (uint32_t w = 0, k = 0; w < MaskT::WORD_COUNT; ++w, out += 64) {
        const Word on = valueMask.template getWord<Word>(w), sel = selection.template getWord<Word>(w);
        if (on == ~Word(0)) {
            std::memcpy(out, active + k, 64 * sizeof(V));
            k += 64;
            continue;
        }
        for (uint32_t b = 0; b < 64; ++b) {
            const bool isOn = (on >> b) & 1;
            const V inactive = (sel >> b) & 1 ? inactive1 : inactive0;
            out[b] = isOn ? active[k] : inactive;
            k += isOn;
        }
    }
}

/// A node's values as readCompressedValues reads them: all MaskT::SIZE of them into @p out,
/// inactive ones rebuilt from the mode byte; @p out null: only walked over (bounds checked).
template <typename V, typename MaskT>
void readValues(Cursor& c, V* out, const MaskT& valueMask, const Codec<V>& codec, Scratch<V>& s) {
    constexpr uint32_t kSize = MaskT::SIZE;
    const int8_t mode = c.get<int8_t>("node compression mode");
    if (mode < openvdb::io::NO_MASK_OR_INACTIVE_VALS || mode > openvdb::io::NO_MASK_AND_ALL_VALS)
        throw Unsupported{"an unknown node compression mode"};
    V inactive0 = mode == openvdb::io::NO_MASK_OR_INACTIVE_VALS ? codec.background : V(-codec.background);
    V inactive1 = codec.background;
    if (mode == openvdb::io::NO_MASK_AND_ONE_INACTIVE_VAL || mode == openvdb::io::MASK_AND_ONE_INACTIVE_VAL ||
        mode == openvdb::io::MASK_AND_TWO_INACTIVE_VALS) {
        inactive0 = c.get<V>("inactive value");
        if (mode == openvdb::io::MASK_AND_TWO_INACTIVE_VALS) inactive1 = c.get<V>("inactive value");
    }
    MaskT selection;
    if (mode == openvdb::io::MASK_AND_NO_INACTIVE_VALS || mode == openvdb::io::MASK_AND_ONE_INACTIVE_VAL ||
        mode == openvdb::io::MASK_AND_TWO_INACTIVE_VALS)
        std::memcpy(&selection.template getWord<typename MaskT::Word>(0), c.take(MaskT::memUsage(), "selection mask"),
                    MaskT::memUsage());
    uint32_t count = kSize;
    if ((codec.compression & openvdb::io::COMPRESS_ACTIVE_MASK) && mode != openvdb::io::NO_MASK_AND_ALL_VALS)
        count = valueMask.countOn();
    if (!out || count == kSize) return readStored(c, out, count, codec, s);
    s.values.resize(count + 1);  // one spare: the branch-free loop below reads one past the last
    readStored(c, s.values.data(), count, codec, s);
    expandActive(out, s.values.data(), valueMask, selection, inactive0, inactive1);
}

template <typename MaskT>
MaskT loadMask(Cursor& c, const char* what) {
    MaskT m;
    std::memcpy(&m.template getWord<typename MaskT::Word>(0), c.take(MaskT::memUsage(), what), MaskT::memUsage());
    return m;
}

// ---- the tree ------------------------------------------------------------------------------

/// Finite active value range and non-finite count, merged across threads (order-free).
struct Stats {
    float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
    uint64_t nonFinite = 0;
    void merge(const Stats& o) {
        lo = std::min(lo, o.lo);
        hi = std::max(hi, o.hi);
        nonFinite += o.nonFinite;
    }
    /// An active value of @p voxels voxels: 0 when it is not finite (counted), else measured.
    float active(float x, uint64_t voxels) {
        if (!std::isfinite(x)) {
            nonFinite += voxels;
            return 0.0f;
        }
        lo = std::min(lo, x);
        hi = std::max(hi, x);
        return x;
    }
};

/// A leaf of the tree (its buffer not yet allocated), to read from [begin, end) of the buffers.
struct LeafJob {
    Leaf* leaf;
    uint64_t begin = 0, end = 0;
};

/// The error of the first damaged leaf in file order, whichever thread finds it.
class FirstError {
public:
    void add(size_t index, const std::string& message) {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (index < index_) index_ = index, message_ = message;
    }
    void throwIfAny() const {
        if (index_ != std::numeric_limits<size_t>::max()) throw Error(message_);
    }

private:
    std::mutex mutex_;
    size_t index_ = std::numeric_limits<size_t>::max();
    std::string message_;
};

/// The range of a leaf's active values (all finite), in mask order with std::min/max: the
/// first of equal extremes wins, as a serial pass over the tree keeps it (only ±0 can tell).
void exactRange(const float* values, const Leaf::NodeMaskType& mask, float& lo, float& hi) {
    for (uint32_t w = 0; w < Leaf::NodeMaskType::WORD_COUNT; ++w)
        for (uint64_t on = mask.getWord<uint64_t>(w); on != 0; on &= on - 1) {
            const float x = values[64 * w + uint32_t(std::countr_zero(on))];
            lo = std::min(lo, x);
            hi = std::max(hi, x);
        }
}

/// Stats::active on every active value of a leaf buffer: non-finite ones zeroed and counted, the
/// range of the rest a vector at a time (sanitizeLeafValues, volume/leaf_values.h). Which of two
/// equal extremes that keeps can differ from exactRange only for zeros (+0 and −0), so a leaf
/// whose extreme is 0 is measured again exactly.
void measureActive(float* values, const Leaf::NodeMaskType& active, Stats& s) {
    Leaf::NodeMaskType mask = active;  // less the non-finite values
    float leafLo, leafHi;
    s.nonFinite += sanitizeLeafValues(values, &mask.getWord<uint64_t>(0), leafLo, leafHi);
    if (leafLo == 0.0f || leafHi == 0.0f) {
        leafLo = std::numeric_limits<float>::max(), leafHi = std::numeric_limits<float>::lowest();
        exactRange(values, mask, leafLo, leafHi);
    }
    if (leafLo <= leafHi) {  // any active value: merge in order, the earlier leaf winning ties
        s.lo = std::min(s.lo, leafLo);
        s.hi = std::max(s.hi, leafHi);
    }
}

bool sameBits(float a, float b) { return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b); }

template <typename V>
class TreeReader {
public:
    TreeReader(const Image& f, const Codec<V>& codec) : f_(f), codec_(codec), bg_(float(codec.background)) {}

    /// The topology in [pos, end): the tree, with every leaf recorded (not yet read).
    std::shared_ptr<FloatTree> readTopology(Cursor& c) {
        auto tree = std::make_shared<FloatTree>(bg_);
        const uint32_t tiles = c.get<uint32_t>("root tile count"), children = c.get<uint32_t>("root child count");
        if (uint64_t(tiles) * (13 + sizeof(V)) + uint64_t(children) * (12 + 2 * Upper::NodeMaskType::memUsage()) >
            c.left())
            c.corrupt("root node tile or child count");
        for (uint32_t n = 0; n < tiles; ++n) {
            const Coord xyz = coord(c, "root tile");
            const V value = c.get<V>("root tile value");
            const uint8_t active = c.get<uint8_t>("root tile state");
            if (active > 1) throw Unsupported{"a root tile state other than 0 or 1"};
            tree->root().addTile(xyz, float(value), active != 0);  // measured below, once the table is final
        }
        Coord previous;
        for (uint32_t n = 0; n < children; ++n) {
            const Coord xyz = coord(c, "root child");
            if (n > 0 && !(previous < xyz)) throw Unsupported{"root children out of order"};
            previous = xyz;
            auto upper = std::make_unique<Upper>(xyz, bg_);
            readInternal(c, *upper);
            tree->root().addChild(upper.release());
        }
        measureRootTiles(tree->root());
        return tree;
    }

    /// Reads every leaf's values from the buffers section @p c, batch by batch: the batch's
    /// chunk headers walked in file order (bounds checked), then its leaves read in parallel.
    /// The first damaged leaf in file order is the error, whatever the threads did.
    Stats readLeaves(Cursor& c) {
        Stats all = stats_;
        for (size_t first = 0; first < leaves_.size(); first += kLeafBatch) {
            const size_t last = std::min(leaves_.size(), first + kLeafBatch);
            const uint64_t begin = c.pos();
            if (f_.willNeed) f_.willNeed(begin, begin + std::min(c.left(), kPrefetchBytes));
            locateLeaves(c, first, last);
            all.merge(readBatch(first, last));
            errors_.throwIfAny();
            if (f_.release) f_.release(begin, c.pos());
        }
        return all;
    }

private:
    void locateLeaves(Cursor& c, size_t first, size_t last) {
        Scratch<V> none;
        for (size_t i = first; i < last; ++i) {
            LeafJob& job = leaves_[i];
            c.take(Leaf::NodeMaskType::memUsage(), "leaf value mask");
            job.begin = c.pos();
            readValues<V>(c, nullptr, job.leaf->getValueMask(), codec_, none);
            job.end = c.pos();
        }
    }

    Stats readBatch(size_t first, size_t last) {
        return tbb::parallel_reduce(
            tbb::blocked_range<size_t>(first, last, kLeafGrain), Stats{},
            [&](const tbb::blocked_range<size_t>& r, Stats s) {
                Scratch<V> scratch;
                for (size_t i = r.begin(); i != r.end(); ++i) readLeaf(i, scratch, s);
                return s;
            },
            [](Stats a, const Stats& b) {
                a.merge(b);
                return a;
            });
    }

    Coord coord(Cursor& c, const char* what) {
        int32_t v[3];
        std::memcpy(v, c.take(12, what), 12);
        const Coord xyz(v[0], v[1], v[2]);
        if ((xyz & ~(Upper::DIM - 1)) != xyz) throw Unsupported{"a root entry off the 4096 grid"};
        return xyz;
    }

    /// An internal node's masks, tile values and children (OpenVDB's readTopology).
    template <typename NodeT>
    void readInternal(Cursor& c, NodeT& node) {
        using Mask = typename NodeT::NodeMaskType;
        const Mask childMask = loadMask<Mask>(c, "child mask"), valueMask = loadMask<Mask>(c, "value mask");
        if (!(childMask & valueMask).isOff()) throw Unsupported{"an active tile under a child node"};
        tiles_.resize(NodeT::NUM_VALUES);
        readValues<V>(c, tiles_.data(), valueMask, codec_, scratch_);
        const uint64_t voxels = uint64_t(NodeT::ChildNodeType::DIM) * NodeT::ChildNodeType::DIM * NodeT::ChildNodeType::DIM;
        for (openvdb::Index i = 0; i < NodeT::NUM_VALUES; ++i) {
            if (childMask.isOn(i)) continue;
            const bool on = valueMask.isOn(i);
            float v = float(tiles_[i]);
            if (on) v = stats_.active(v, voxels);
            if (on || !sameBits(v, bg_)) node.addTile(i, v, on);
        }
        for (auto it = childMask.beginOn(); it; ++it) {
            const Coord origin = node.offsetToGlobalCoord(it.pos());
            if constexpr (std::is_same_v<NodeT, Upper>) {
                auto lower = std::make_unique<Lower>(origin, bg_);
                readInternal(c, *lower);
                node.addChild(lower.release());
            } else {
                auto leaf = std::make_unique<Leaf>(openvdb::PartialCreate(), origin, bg_);  // no buffer yet
                leaf->setValueMask(loadMask<Leaf::NodeMaskType>(c, "leaf value mask"));
                // Its buffer now, beside the node (the values are written in parallel later): the
                // renderer reads a leaf's mask and values together, and with the buffers allocated
                // by the worker threads, away from their nodes, far views streamed 13 % slower
                // (Engine far 400², session 6; 6 % with this). At most 2 KiB per 64 bytes of mask in
                // the file, as OpenVDB's own read allocates.
                leaf->allocate();
                leaves_.push_back(LeafJob{leaf.get()});
                node.addChild(leaf.release());
            }
        }
    }

    void measureRootTiles(Root& root) {
        constexpr uint64_t voxels = uint64_t(Upper::DIM) * Upper::DIM * Upper::DIM;
        for (auto it = root.beginValueOn(); it; ++it) it.setValue(stats_.active(*it, voxels));
    }

    void readLeaf(size_t index, Scratch<V>& scratch, Stats& s) {
        const LeafJob& job = leaves_[index];
        try {
            const Leaf::NodeMaskType& mask = job.leaf->getValueMask();
            job.leaf->allocate();
            float* out = job.leaf->buffer().data();
            Cursor c(f_, job.begin, job.end);
            if constexpr (std::is_same_v<V, float>) {
                readValues<V>(c, out, mask, codec_, scratch);
            } else {
                V wide[Leaf::SIZE];
                readValues<V>(c, wide, mask, codec_, scratch);
                for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) out[i] = float(wide[i]);
            }
            measureActive(out, mask, s);
        } catch (const Error& e) {
            errors_.add(index, e.what());
        } catch (const std::bad_alloc&) {
            errors_.add(index, f_.label + ": out of memory reading the grid");
        }
    }

    const Image& f_;
    Codec<V> codec_;
    float bg_;
    std::vector<LeafJob> leaves_;
    std::vector<V> tiles_;
    Scratch<V> scratch_;
    Stats stats_;
    FirstError errors_;
};

/// The linear map OpenVDB's Transform::read makes of the grid's transform (a type vdbMapBytes
/// knows), read by OpenVDB's own map class from exactly its bytes (readLinearMap: header-only
/// code, no registry): no simplification, the map type kept, a singular map left for
/// loadVolume's check to name. @p bytes gets the transform's bytes, type name included.
openvdb::math::MapBase::Ptr readTransform(Cursor& c, std::string& bytes) {
    const uint64_t begin = c.pos();
    const char* start = c.here();
    const std::string type = c.string("grid transform type");
    const uint64_t mapBytes = vdbMapBytes(type);
    if (mapBytes == 0) throw Unsupported{"a map type not read here"};
    const char* map = c.here();
    c.take(mapBytes, "grid transform");
    bytes.assign(start, c.pos() - begin);
    try {
        return readLinearMap(type, std::string_view(map, mapBytes));
    } catch (const std::exception& e) {
        c.corrupt("grid transform (" + std::string(e.what()) + ")");
    }
}

/// The grid's "name" as GridBase::getName() gives it after MetaMap::readMeta, from its metadata
/// block (@p bytes gets the block): the last "name" item's string, "" without one. Blocks
/// MetaMap::readMeta would refuse or read otherwise (an empty item name, an item name given two
/// types, a non-string "name") are left to OpenVDB.
std::string readGridName(Cursor& c, std::string& bytes) {
    const char* start = c.here();
    const uint64_t begin = c.pos();
    std::vector<std::pair<std::string, std::string>> types;  // item name, its type
    std::string name;
    const char* unsupported = nullptr;  // after the whole block: a corrupt item is still named as such
    walkMetadata(c, [&](std::string_view item, const std::string& type, std::string_view value) {
        if (item.empty()) unsupported = "a metadata item without a name";
        const auto seen = std::find_if(types.begin(), types.end(), [&](const auto& t) { return t.first == item; });
        if (seen == types.end()) types.emplace_back(item, type);
        else if (seen->second != type) unsupported = "a metadata item given two types";
        if (item == "name") {
            if (type != "string") unsupported = "a grid name that is not a string";
            name.assign(value);
        }
    });
    if (unsupported) throw Unsupported{unsupported};
    bytes.assign(start, c.pos() - begin);
    return name;
}

/// The grid of descriptor @p d: its header and topology in [gridPos, blockPos), its leaf
/// buffers in [blockPos, endPos).
template <typename V>
ReadGrid readGrid(const Image& f, const Descriptor& d) {
    Cursor head(f, uint64_t(d.gridPos), uint64_t(d.blockPos));
    Codec<V> codec;
    codec.compression = head.get<uint32_t>("grid compression flags");
    codec.half = d.half;
    ReadGrid out;
    out.name = readGridName(head, out.metadata);
    out.map = readTransform(head, out.transform);
    if (head.get<int32_t>("tree buffer count") != 1) throw Unsupported{"a tree buffer count other than 1"};
    codec.background = head.get<V>("root background value");
    TreeReader<V> reader(f, codec);
    std::shared_ptr<FloatTree> tree = reader.readTopology(head);
    if (head.pos() != uint64_t(d.blockPos)) throw Unsupported{"topology that does not end at the grid's data offset"};
    Cursor buffers(f, uint64_t(d.blockPos), uint64_t(d.endPos));
    const Stats stats = reader.readLeaves(buffers);

    out.activeVoxels = tree->activeVoxelCount();
    out.tree = std::move(tree);
    out.nonFiniteCount = stats.nonFinite;
    out.valueMin = stats.lo <= stats.hi ? stats.lo : 0.0f;
    out.valueMax = stats.lo <= stats.hi ? stats.hi : 0.0f;
    return out;
}

/// The file mapped read-only. willNeed prefaults a range (one call instead of a fault per 16
/// pages), release drops what lies before an offset from this process (the page cache keeps it).
class MappedFile {
public:
    explicit MappedFile(const std::string& path) {
        const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) throw Error(path + ": cannot open for reading (" + std::strerror(errno) + ")");
        struct stat st {};
        if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
            ::close(fd);
            throw Error(path + ": not a regular file");
        }
        size_ = uint64_t(st.st_size);
        if (size_ > 0) {
            void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
            if (p == MAP_FAILED) {
                ::close(fd);
                throw Error(path + ": cannot map for reading (" + std::strerror(errno) + ")");
            }
            data_ = static_cast<const char*>(p);
        }
        ::close(fd);
    }
    ~MappedFile() {
        if (data_) ::munmap(const_cast<char*>(data_), size_);
    }
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;
    const char* data() const { return data_; }
    uint64_t size() const { return size_; }
    void willNeed(uint64_t begin, uint64_t end) const {
        begin &= ~(kPage - 1);
        if (end > begin) ::madvise(const_cast<char*>(data_) + begin, end - begin, MADV_POPULATE_READ);  // a hint: errors ignored
    }
    void release(uint64_t end) {
        end &= ~(kPage - 1);
        if (end <= released_) return;
        ::madvise(const_cast<char*>(data_) + released_, end - released_, MADV_DONTNEED);
        released_ = end;
    }

private:
    static constexpr uint64_t kPage = 4096;
    const char* data_ = nullptr;
    uint64_t size_ = 0, released_ = 0;
};

}  // namespace

namespace {
std::optional<ReadGrid> readImage(const Image& f, const std::string& gridName, std::string* unsupported) {
    try {
        const std::vector<Descriptor> all = readDescriptors(f);
        const Descriptor& d = chooseGrid(all, gridName);
        return isFloat(d.type) ? readGrid<float>(f, d) : readGrid<double>(f, d);
    } catch (const Unsupported& u) {
        if (unsupported) *unsupported = u.why;
        return std::nullopt;
    } catch (const std::bad_alloc&) {
        throw Error(f.label + ": out of memory reading the grid");
    }
}
}  // namespace

std::optional<ReadGrid> readVdbGrid(const char* data, uint64_t size, const std::string& label,
                                    const std::string& gridName, std::string* unsupported) {
    return readImage(Image{data, size, label}, gridName, unsupported);
}

std::optional<ReadGrid> readVdbGrid(const std::string& path, const std::string& gridName, std::string* unsupported) {
    MappedFile file(path);
    Image f{file.data(), file.size(), path};
    f.willNeed = [&](uint64_t begin, uint64_t end) { file.willNeed(begin, end); };
    f.release = [&](uint64_t, uint64_t end) { file.release(end); };
    return readImage(f, gridName, unsupported);
}

openvdb::FloatGrid::Ptr toOpenVdbGrid(const ReadGrid& read) {
    initOpenVdb();  // the metadata and map registries
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(read.tree);
    MemoryStream meta(read.metadata);
    openvdb::MetaMap map;
    map.readMeta(meta);
    map.removeMeta("file_delayed_load");  // GridBase::META_FILE_DELAYED_LOAD (data in libopenvdb: not named here)
    static_cast<openvdb::MetaMap&>(*grid) = map;
    MemoryStream in(read.transform);
    openvdb::io::setCurrentVersion(in);  // the map layout of file versions 219 and later
    openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform();
    transform->read(in);
    grid->setTransform(transform);
    return grid;
}

}  // namespace vdbsplat
