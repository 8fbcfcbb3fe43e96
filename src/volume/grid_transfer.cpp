// volume/grid_transfer.cpp — the transfer form of a float tree (see grid_transfer.h).
// Layout (native byte order; the two ends are the same binary on the same machine), every
// part starting at a multiple of 8 bytes:
//   Header (56 bytes: magic, total bytes, leaf and tile counts, name/transform/log lengths,
//   grid class, background), name, transform (Transform::write: map type string + map
//   data), log, then tileCount × Tile (24 bytes), then leafCount × Leaf (2128 bytes:
//   origin, 8 mask words, 512 floats).
#include "volume/grid_transfer.h"

#include <openvdb/io/io.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "util/error.h"
#include "volume/vdb_check.h"

namespace vdbsplat {

namespace {

using FloatTree = openvdb::FloatTree;
using FloatLeaf = FloatTree::LeafNodeType;

constexpr char kMagic[8] = {'V', 'D', 'B', 'S', 'X', 'F', 'R', '1'};
constexpr uint64_t kMaxNameBytes = 1 << 16;       ///< grid names longer than this are refused
constexpr uint64_t kMaxTransformBytes = 1024;     ///< a linear map is at most 4 + 64 + 144 bytes
constexpr uint64_t kMaxLogBytes = 1 << 16;        ///< the child keeps the first 64 KiB of its log
/// Leaves built (in parallel) per chunk: 544 KB, a buffer small enough that its own first-touch
/// page faults cost little (on the development VM a fault costs ~20-30 µs).
constexpr uint64_t kLeafChunk = 256;

struct Header {
    char magic[8];
    uint64_t totalBytes;
    uint64_t leafCount;
    uint64_t tileCount;
    uint32_t nameBytes, transformBytes, logBytes;
    int32_t gridClass;
    float background;
    uint32_t reserved;
};
static_assert(sizeof(Header) == 56);

struct Tile {
    int32_t x, y, z;
    uint32_t level;  ///< 1: an 8³ tile in a lowest internal node, 2: 128³, 3: a 4096³ root tile
    float value;
    uint32_t active;
};
static_assert(sizeof(Tile) == 24);

constexpr uint64_t kMaskWords = FloatLeaf::NodeMaskType::WORD_COUNT;
constexpr uint64_t kLeafValues = FloatLeaf::SIZE;
constexpr uint64_t kLeafBytes = 16 + 8 * kMaskWords + 4 * kLeafValues;
static_assert(kLeafBytes == 2128);

uint64_t padded(uint64_t n) { return (n + 7) & ~uint64_t(7); }

/// Side of a tile's cube at @p level (1..3) of a FloatTree (8, 128, 4096).
int32_t tileDim(uint32_t level) {
    using Root = FloatTree::RootNodeType;
    using Upper = Root::ChildNodeType;
    using Lower = Upper::ChildNodeType;
    return level == 1 ? int32_t(Lower::ChildNodeType::DIM) : level == 2 ? int32_t(Lower::DIM) : int32_t(Upper::DIM);
}

// --- encoding (the child) --------------------------------------------------

/// Buffered sequential writes to a file descriptor.
class FdWriter {
public:
    FdWriter(int fd, const std::string& label) : fd_(fd), label_(label) { buffer_.reserve(kCapacity); }
    void put(const void* data, size_t n) {
        const char* p = static_cast<const char*>(data);
        while (n > 0) {
            const size_t take = std::min(n, kCapacity - buffer_.size());
            buffer_.insert(buffer_.end(), p, p + take);
            p += take;
            n -= take;
            if (buffer_.size() == kCapacity) flush();
        }
    }
    void pad() {
        static const char zeros[8] = {};
        put(zeros, padded(written_ + buffer_.size()) - (written_ + buffer_.size()));
    }
    void flush() {
        for (size_t done = 0; done < buffer_.size();) {
            const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) throw Error(label_ + ": cannot hand the grid over (" + std::strerror(errno) + ")");
            done += size_t(n);
        }
        written_ += buffer_.size();
        buffer_.clear();
    }

private:
    static constexpr size_t kCapacity = 256 << 10;  ///< small: its own page faults are not free
    int fd_;
    std::string label_;
    std::vector<char> buffer_;
    uint64_t written_ = 0;
};

/// Every tile of an internal node that is active or not the background.
template <typename NodeT, typename ValueT>
void collectNodeTiles(const NodeT& node, uint32_t level, const ValueT& background, std::vector<Tile>& tiles) {
    const auto* table = node.getTable();
    const auto& children = node.getChildMask();
    const auto& values = node.getValueMask();
    for (openvdb::Index i = 0; i < NodeT::NUM_VALUES; ++i) {
        if (children.isOn(i)) continue;
        const ValueT v = table[i].getValue();
        const bool on = values.isOn(i);
        if (!on && v == background) continue;
        const openvdb::Coord c = node.offsetToGlobalCoord(i);
        tiles.push_back({c.x(), c.y(), c.z(), level, float(v), on ? 1u : 0u});
    }
}

template <typename TreeT>
std::vector<Tile> collectTiles(const TreeT& tree) {
    using ValueT = typename TreeT::ValueType;
    const ValueT background = tree.background();
    std::vector<Tile> tiles;
    const auto& root = tree.root();
    for (auto it = root.cbeginValueAll(); it; ++it) {
        if (!it.isValueOn() && *it == background) continue;
        const openvdb::Coord c = it.getCoord();
        tiles.push_back({c.x(), c.y(), c.z(), 3u, float(*it), it.isValueOn() ? 1u : 0u});
    }
    for (auto upper = root.cbeginChildOn(); upper; ++upper) {
        collectNodeTiles(*upper, 2u, background, tiles);
        for (auto lower = upper->cbeginChildOn(); lower; ++lower) collectNodeTiles(*lower, 1u, background, tiles);
    }
    return tiles;
}

template <typename TreeT>
void encodeTree(const TreeT& tree, const openvdb::GridBase& grid, const std::string& log, FdWriter& out) {
    std::ostringstream transform;
    grid.transform().write(transform);
    const std::string xform = transform.str(), name = grid.getName();
    const std::string logText = log.substr(0, kMaxLogBytes);
    const std::vector<Tile> tiles = collectTiles(tree);
    const uint64_t leafCount = tree.leafCount();

    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.leafCount = leafCount;
    h.tileCount = tiles.size();
    h.nameBytes = uint32_t(std::min<uint64_t>(name.size(), kMaxNameBytes + 1));  // longer: refused there
    h.transformBytes = uint32_t(std::min<uint64_t>(xform.size(), kMaxTransformBytes + 1));
    h.logBytes = uint32_t(logText.size());
    h.gridClass = int32_t(grid.getGridClass());
    h.background = float(tree.background());
    h.totalBytes = sizeof(Header) + padded(h.nameBytes) + padded(h.transformBytes) + padded(h.logBytes) +
                   tiles.size() * sizeof(Tile) + leafCount * kLeafBytes;
    out.put(&h, sizeof h);
    out.put(name.data(), h.nameBytes);
    out.pad();
    out.put(xform.data(), h.transformBytes);
    out.pad();
    out.put(logText.data(), h.logBytes);
    out.pad();
    out.put(tiles.data(), tiles.size() * sizeof(Tile));

    char record[kLeafBytes];
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        const openvdb::Coord o = leaf->origin();
        const int32_t origin[4] = {o.x(), o.y(), o.z(), 0};
        std::memcpy(record, origin, 16);
        const auto& mask = leaf->getValueMask();
        for (uint64_t w = 0; w < kMaskWords; ++w) {
            const uint64_t word = mask.template getWord<uint64_t>(openvdb::Index(w));
            std::memcpy(record + 16 + 8 * w, &word, 8);
        }
        const auto* values = leaf->buffer().data();
        if constexpr (std::is_same_v<typename TreeT::ValueType, float>) {
            std::memcpy(record + 16 + 8 * kMaskWords, values, 4 * kLeafValues);
        } else {
            float converted[kLeafValues];
            for (uint64_t i = 0; i < kLeafValues; ++i) converted[i] = float(values[i]);
            std::memcpy(record + 16 + 8 * kMaskWords, converted, sizeof converted);
        }
        out.put(record, kLeafBytes);
    }
    out.flush();
}

void encode(const openvdb::GridBase& grid, const std::string& log, FdWriter& out, const std::string& label) {
    if (const auto* f = dynamic_cast<const openvdb::FloatGrid*>(&grid)) return encodeTree(f->tree(), grid, log, out);
    if (const auto* d = dynamic_cast<const openvdb::DoubleGrid*>(&grid)) return encodeTree(d->tree(), grid, log, out);
    throw Error(label + ": grid '" + grid.getName() + "' holds " + grid.valueType() +
                " values; only float and double grids can be rendered");
}

// --- decoding (the parent) -------------------------------------------------

struct ValueStats {
    uint64_t active = 0, nonFinite = 0;
    float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
    void add(const ValueStats& o) {
        active += o.active;
        nonFinite += o.nonFinite;
        lo = std::min(lo, o.lo);
        hi = std::max(hi, o.hi);
    }
};

/// Copies one leaf record into @p leaf; non-finite active values become 0.
void fillLeaf(const char* record, FloatLeaf& leaf, ValueStats& stats) {
    uint64_t words[kMaskWords];
    std::memcpy(words, record + 16, sizeof words);
    auto& mask = leaf.getValueMask();
    for (uint64_t w = 0; w < kMaskWords; ++w) mask.template getWord<uint64_t>(openvdb::Index(w)) = words[w];
    float* values = leaf.buffer().data();
    std::memcpy(values, record + 16 + 8 * kMaskWords, 4 * kLeafValues);
    for (uint64_t w = 0; w < kMaskWords; ++w) {
        stats.active += uint64_t(__builtin_popcountll(words[w]));
        for (uint64_t bits = words[w]; bits; bits &= bits - 1) {
            float& x = values[64 * w + uint64_t(__builtin_ctzll(bits))];
            if (!std::isfinite(x)) {
                x = 0.0f;
                ++stats.nonFinite;
                continue;
            }
            stats.lo = std::min(stats.lo, x);
            stats.hi = std::max(stats.hi, x);
        }
    }
}

class Decoder {
public:
    Decoder(const TransferSource& source, const std::string& label, std::vector<std::unique_ptr<FloatLeaf>>* pool)
        : source_(source), size_(source.size), label_(label), pool_(pool) {}

    DecodedGrid run() {
        readHeader();
        DecodedGrid out;
        const std::string strings = bytes(sizeof(Header), tilesAt_ - sizeof(Header));
        out.log = strings.substr(logAt_ - sizeof(Header), h_.logBytes);
        auto tree = std::make_shared<FloatTree>(h_.background);
        auto grid = openvdb::FloatGrid::create(tree);
        grid->setTransform(transform(strings.substr(transformAt_ - sizeof(Header), h_.transformBytes)));
        grid->setName(strings.substr(0, h_.nameBytes));
        grid->setGridClass(openvdb::GridClass(h_.gridClass));
        std::vector<Tile> tiles(h_.tileCount);
        if (!tiles.empty()) read(tilesAt_, tiles.size() * sizeof(Tile), tiles.data());
        ValueStats stats;
        buildLeaves(*tree, stats);
        addTiles(*tree, tiles, stats);
        if (tree->leafCount() != h_.leafCount) damaged("leaves overlap");
        const uint64_t active = tree->activeVoxelCount();
        if (active != stats.active) damaged("tiles or leaves overlap");
        out.grid = grid;
        out.activeVoxels = active;
        out.nonFiniteCount = stats.nonFinite;
        if (stats.lo > stats.hi) stats.lo = stats.hi = 0.0f;  // every value was non-finite
        out.valueMin = stats.lo;
        out.valueMax = stats.hi;
        return out;
    }

private:
    [[noreturn]] void damaged(const std::string& what) const {
        throw Error(label_ + ": damaged grid transfer (" + what + ")");
    }

    /// @p n bytes at @p offset (both already checked against the size).
    void read(uint64_t offset, uint64_t n, void* to) const {
        if (offset > size_ || n > size_ - offset || !source_.read(offset, n, to)) damaged("cannot read it");
    }
    std::string bytes(uint64_t offset, uint64_t n) const {
        std::string text(n, '\0');
        read(offset, n, text.data());
        return text;
    }

    void readHeader() {
        if (size_ < sizeof(Header)) damaged("only " + std::to_string(size_) + " bytes");
        read(0, sizeof h_, &h_);
        if (std::memcmp(h_.magic, kMagic, sizeof kMagic) != 0) damaged("wrong magic");
        if (h_.totalBytes != size_) damaged("size " + std::to_string(size_) + ", header says " + std::to_string(h_.totalBytes));
        if (h_.nameBytes > kMaxNameBytes) damaged("grid name too long");
        if (h_.transformBytes > kMaxTransformBytes) damaged("transform too long");
        if (h_.logBytes > kMaxLogBytes) damaged("log too long");
        if (h_.gridClass < 0 || h_.gridClass >= openvdb::NUM_GRID_CLASSES) damaged("grid class");
        transformAt_ = sizeof(Header) + padded(h_.nameBytes);
        logAt_ = transformAt_ + padded(h_.transformBytes);
        tilesAt_ = logAt_ + padded(h_.logBytes);  // ≤ 56 + 3·2^16+24: no overflow
        if (tilesAt_ > size_) damaged("strings past the end");
        const uint64_t rest = size_ - tilesAt_;
        if (h_.tileCount > rest / sizeof(Tile)) damaged("tile count " + std::to_string(h_.tileCount));
        leavesAt_ = tilesAt_ + h_.tileCount * sizeof(Tile);
        if (h_.leafCount > (size_ - leavesAt_) / kLeafBytes) damaged("leaf count " + std::to_string(h_.leafCount));
        if (leavesAt_ + h_.leafCount * kLeafBytes != size_) damaged("counts do not add up to the size");
        if (h_.leafCount > std::numeric_limits<openvdb::Index32>::max()) damaged("leaf count");
    }

    /// The transform, after checking that its bytes are one linear map of the known layout.
    openvdb::math::Transform::Ptr transform(const std::string& bytes) const {
        const uint64_t n = bytes.size();
        uint32_t nameLength = 0;
        if (n < 4) damaged("transform");
        std::memcpy(&nameLength, bytes.data(), 4);
        if (nameLength > 64 || 4 + uint64_t(nameLength) > n) damaged("transform type");
        const std::string type = bytes.substr(4, nameLength);
        const uint64_t mapBytes = vdbMapBytes(type);
        if (mapBytes == 0 || 4 + nameLength + mapBytes != n) damaged("transform of type '" + type + "'");
        std::istringstream in(bytes);
        openvdb::io::setCurrentVersion(in);
        auto xform = std::make_shared<openvdb::math::Transform>();
        try {
            xform->read(in);
        } catch (const std::exception& e) {
            damaged(std::string("transform: ") + e.what());
        }
        if (!in) damaged("transform");
        return xform;
    }

    void buildLeaves(FloatTree& tree, ValueStats& stats) {
        openvdb::tree::ValueAccessor<FloatTree> acc(tree);
        const float background = h_.background;
        std::vector<char> chunk(std::min(kLeafChunk, h_.leafCount) * kLeafBytes);
        for (uint64_t first = 0; first < h_.leafCount; first += kLeafChunk) {
            const uint64_t count = std::min(kLeafChunk, h_.leafCount - first);
            read(leavesAt_ + first * kLeafBytes, count * kLeafBytes, chunk.data());
            std::vector<std::unique_ptr<FloatLeaf>> leaves(count);
            const uint64_t pooled = pool_ && pool_->size() > first ? std::min(count, pool_->size() - first) : 0;
            for (uint64_t i = 0; i < pooled; ++i) leaves[i] = std::move((*pool_)[first + i]);
            std::atomic<bool> misaligned{false};
            const ValueStats part = tbb::parallel_reduce(
                tbb::blocked_range<uint64_t>(0, count, 64), ValueStats{},
                [&](const tbb::blocked_range<uint64_t>& r, ValueStats s) {
                    for (uint64_t i = r.begin(); i != r.end(); ++i) {
                        const char* record = chunk.data() + i * kLeafBytes;
                        int32_t o[3];
                        std::memcpy(o, record, sizeof o);
                        if (((o[0] | o[1] | o[2]) & int32_t(FloatLeaf::DIM - 1)) != 0) {
                            misaligned = true;
                            continue;
                        }
                        const openvdb::Coord origin(o[0], o[1], o[2]);
                        if (leaves[i]) leaves[i]->setOrigin(origin);  // allocated (and its pages touched) while the child read
                        else leaves[i] = std::make_unique<FloatLeaf>(origin, background);
                        fillLeaf(record, *leaves[i], s);
                    }
                    return s;
                },
                [](ValueStats a, const ValueStats& b) {
                    a.add(b);
                    return a;
                });
            if (misaligned) damaged("leaf origin not on the 8-voxel grid");
            stats.add(part);
            for (auto& leaf : leaves) acc.addLeaf(leaf.release());
            source_.release(leavesAt_ + first * kLeafBytes, leavesAt_ + (first + count) * kLeafBytes);
        }
        if (pool_) pool_->clear();  // what the estimate allocated beyond the leaf count
    }

    void addTiles(FloatTree& tree, std::vector<Tile>& tiles, ValueStats& stats) {
        for (Tile& t : tiles) {
            if (t.level < 1 || t.level > 3 || t.active > 1) damaged("tile level or state");
            const int32_t dim = tileDim(t.level);
            if (((t.x | t.y | t.z) & (dim - 1)) != 0) damaged("tile origin not on its level's grid");
            if (t.active) {
                const uint64_t voxels = uint64_t(dim) * uint64_t(dim) * uint64_t(dim);
                if (__builtin_add_overflow(stats.active, voxels, &stats.active)) damaged("active voxel count");
                if (!std::isfinite(t.value)) {
                    t.value = 0.0f;
                    stats.nonFinite += voxels;
                } else {
                    stats.lo = std::min(stats.lo, t.value);
                    stats.hi = std::max(stats.hi, t.value);
                }
            }
            tree.addTile(t.level, openvdb::Coord(t.x, t.y, t.z), t.value, t.active != 0);
        }
    }

    const TransferSource& source_;
    uint64_t size_;
    std::string label_;
    std::vector<std::unique_ptr<FloatLeaf>>* pool_;
    Header h_{};
    uint64_t transformAt_ = 0, logAt_ = 0, tilesAt_ = 0, leavesAt_ = 0;
};

}  // namespace

void encodeGridTransfer(const openvdb::GridBase& grid, const std::string& log, int fd, const std::string& label) {
    FdWriter out(fd, label);
    encode(grid, log, out, label);
}

std::vector<char> encodeGridTransfer(const openvdb::GridBase& grid, const std::string& log) {
    const int fd = ::memfd_create("vdbsplat-grid", MFD_CLOEXEC);
    if (fd < 0) throw Error("cannot make a memfd for a grid transfer");
    std::vector<char> bytes;
    try {
        encodeGridTransfer(grid, log, fd, "<memory>");
        const off_t size = ::lseek(fd, 0, SEEK_END);
        bytes.resize(size_t(size));
        if (::pread(fd, bytes.data(), bytes.size(), 0) != ssize_t(bytes.size())) throw Error("cannot read a grid transfer back");
    } catch (...) {
        ::close(fd);
        throw;
    }
    ::close(fd);
    return bytes;
}

DecodedGrid decodeGridTransfer(const char* data, uint64_t size, const std::string& label,
                               const std::function<void(uint64_t, uint64_t)>& release) {
    TransferSource source;
    source.size = size;
    source.read = [data](uint64_t offset, uint64_t n, void* to) {
        std::memcpy(to, data + offset, n);
        return true;
    };
    if (release) source.release = release;
    return Decoder(source, label, nullptr).run();
}

TransferMemory::TransferMemory(const std::string& label) : label_(label) {
    fd_ = ::memfd_create("vdbsplat-grid", MFD_CLOEXEC);
    if (fd_ < 0) throw Error(label + ": cannot hand a grid over (memfd_create: " + std::strerror(errno) + ")");
}

TransferMemory::~TransferMemory() {
    if (fd_ >= 0) ::close(fd_);
}

void TransferMemory::preallocate(uint64_t leaves) {
    // The memfd's pages too, in one call instead of one allocation per page as the child
    // writes (beyond the end of the file: its size stays what the child writes).
    ::fallocate(fd_, FALLOC_FL_KEEP_SIZE, 0, off_t(leaves * kLeafBytes + (1 << 16)));
    pool_.reserve(leaves);
    for (uint64_t i = 0; i < leaves; ++i) pool_.push_back(std::make_unique<FloatLeaf>(openvdb::Coord(0), 0.0f));
}

DecodedGrid TransferMemory::decode() {
    struct stat st {};
    if (::fstat(fd_, &st) != 0) throw Error(label_ + ": cannot hand a grid over (fstat failed)");
    TransferSource source;
    source.size = uint64_t(st.st_size);
    source.read = [this](uint64_t offset, uint64_t n, void* to) {
        for (uint64_t done = 0; done < n;) {
            const ssize_t got = ::pread(fd_, static_cast<char*>(to) + done, n - done, off_t(offset + done));
            if (got < 0 && errno == EINTR) continue;
            if (got <= 0) return false;
            done += uint64_t(got);
        }
        return true;
    };
    // Each chunk of leaves, once in the tree, is punched out of the memfd: the transfer and
    // the tree are never both whole in memory.
    uint64_t freed = 0;
    source.release = [&](uint64_t, uint64_t end) {
        const uint64_t to = end & ~uint64_t(4095);
        if (to > freed && ::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, off_t(freed), off_t(to - freed)) == 0)
            freed = to;
    };
    return Decoder(source, label_, &pool_).run();
}

}  // namespace vdbsplat
