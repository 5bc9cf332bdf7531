#include "laser_dpslam/slam/dpslam_map.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>

#include <sys/mman.h>

#include "laser_dpslam/common/fast_exp.h"

namespace laser_dpslam {

static_assert(sizeof(MapEntry) == 16, "MapEntry grew: the map's memory is mostly entries");
static_assert(DpSlamMap::kMaxNodeId <= 32767, "LookupCache rows hold entry indices in 16 bits");
static_assert(sizeof(DpSlamMap::CellWrite) == 16, "CellWrite grew: a scan into new space plans millions");

namespace {
void requireNodeId(int node) {
  if (node < 0 || node > DpSlamMap::kMaxNodeId) {
    throw std::out_of_range("DpSlamMap: node ID " + std::to_string(node) + " outside [0, " +
                            std::to_string(DpSlamMap::kMaxNodeId) + "]");
  }
}
}  // namespace

// ---------------------------------------------------------------------------------------------------
// Entry blocks: size classes of capacity 1, 2, 3, 4, 6, 8, 12, … entries (steps of 1.5 and 4/3: a cell
// seen by every particle holds a few more entries than there are particles, and doubling left a third
// of the pool empty), carved out of fixed-size chunks so that a growing map never reallocates (and
// copies) what it already holds. Freed blocks go to a per-class free list and are reused first; when
// many of a class are free, compact() moves the live ones down and returns the emptied chunks (the
// particles' entries come and go by the million, and a class's free blocks serve no other class).
// Chunks are mapped pages of their own, so that freeing one gives its memory back to the system
// whatever the heap around it looks like.
class DpSlamMap::EntryPool {
 public:
  static constexpr int kClasses = 30;        ///< up to 32768 entries: one per node ID
  static constexpr int kChunkEntries = 16384;  ///< per chunk (or one block, if larger)

  static constexpr std::uint32_t capacity(int cls) {
    return cls == 0 ? 1u : (cls & 1) ? 1u << ((cls + 1) / 2) : 3u << (cls / 2 - 1);
  }
  MapEntry* at(int cls, std::uint32_t block) const {
    const std::uint32_t per = blocksPerChunk(cls);
    return chunks_[cls][block / per].get() + static_cast<std::size_t>(block % per) * capacity(cls);
  }
  std::uint32_t allocate(int cls) {
    static_assert(capacity(kClasses - 1) > kMaxNodeId, "a cell's entries (one per node ID) fit the largest class");
    if (cls >= kClasses) throw std::length_error("DpSlamMap: too many entries in one cell");
    if (!free_[cls].empty()) {
      const std::uint32_t b = free_[cls].back();
      free_[cls].pop_back();
      return b;
    }
    if (next_[cls] == chunks_[cls].size() * blocksPerChunk(cls)) chunks_[cls].push_back(mapChunk(chunkBytes(cls)));
    return next_[cls]++;
  }
  void release(int cls, std::uint32_t block) { free_[cls].push_back(block); }
  /// Whether compact(cls) would give back enough to be worth its pass over the class: a quarter of
  /// its blocks and at least a chunk free.
  bool wantsCompaction(int cls) const {
    const std::size_t n = free_[cls].size();
    return n >= blocksPerChunk(cls) && 4 * n >= next_[cls];
  }
  /// Moves the live blocks of `cls` into the lowest block numbers and frees the chunks left empty;
  /// moved(old, new) is called after each block's entries were copied to `new`.
  template <class F>
  void compact(int cls, F&& moved) {
    const std::uint32_t live = next_[cls] - static_cast<std::uint32_t>(free_[cls].size());
    std::vector<std::uint32_t> holes;  // free blocks below `live`: exactly as many as live blocks above
    std::vector<bool> free_above(next_[cls] - live, false);
    for (std::uint32_t b : free_[cls]) {
      if (b < live) holes.push_back(b);
      else free_above[b - live] = true;
    }
    std::size_t h = 0;
    for (std::uint32_t b = live; b < next_[cls]; ++b) {
      if (free_above[b - live]) continue;
      std::memcpy(static_cast<void*>(at(cls, holes[h])), at(cls, b), sizeof(MapEntry) * capacity(cls));
      moved(b, holes[h++]);
    }
    next_[cls] = live;
    std::vector<std::uint32_t>().swap(free_[cls]);
    chunks_[cls].resize((live + blocksPerChunk(cls) - 1) / blocksPerChunk(cls));
  }
  std::size_t bytes() const {
    std::size_t b = 0;
    for (int c = 0; c < kClasses; ++c) {
      b += chunks_[c].size() * chunkBytes(c) + free_[c].capacity() * sizeof(std::uint32_t);
    }
    return b;
  }

 private:
  /// Pages from mmap, unmapped on destruction; MapEntry is trivially copyable, written before read.
  struct Unmap {
    std::size_t bytes = 0;
    void operator()(MapEntry* p) const { ::munmap(p, bytes); }
  };
  using Chunk = std::unique_ptr<MapEntry, Unmap>;
  static Chunk mapChunk(std::size_t bytes) {
    void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    return Chunk(static_cast<MapEntry*>(p), Unmap{bytes});
  }
  static std::uint32_t blocksPerChunk(int cls) { return std::max(1u, kChunkEntries / capacity(cls)); }
  static std::size_t chunkBytes(int cls) {
    return static_cast<std::size_t>(blocksPerChunk(cls)) * capacity(cls) * sizeof(MapEntry);
  }
  std::vector<Chunk> chunks_[kClasses];
  std::vector<std::uint32_t> free_[kClasses];
  std::uint32_t next_[kClasses] = {};
};

// ---------------------------------------------------------------------------------------------------
void LookupCache::begin(const AncestryTree& tree, const std::vector<int>& slot_nodes, bool every_particle) {
  slot_nodes_ = slot_nodes;
  every_particle_ = every_particle;
  covered_.clear();
  parent_.assign(tree.idCapacity(), -1);
  for (std::size_t i = 0; i < tree.idCapacity(); ++i) {
    if (tree.valid(static_cast<int>(i))) parent_[i] = tree.parent(static_cast<int>(i));
  }
  root_ = tree.root();
  if (memo_.size() < tree.idCapacity()) {
    memo_.resize(tree.idCapacity(), -1);
    memo_stamp_.resize(tree.idCapacity(), 0);
  }
  slot_masks_ = slot_nodes_.size() <= 64;
  if (slot_masks_) {
    descendants_.assign(parent_.size(), 0);
    depth_.assign(parent_.size(), -1);
    for (std::size_t s = 0; s < slot_nodes_.size(); ++s) {
      for (int n = slot_nodes_[s]; n >= 0; n = parent_[n]) descendants_[n] |= std::uint64_t{1} << s;
    }
    for (std::size_t i = 0; i < parent_.size(); ++i) {
      if (!descendants_[i]) continue;
      int d = 0;
      for (int n = parent_[i]; n >= 0; n = parent_[n]) ++d;
      depth_[i] = d;
    }
  }
  rows_.clear();
  // The rows of a tile no trace entered for a while go: the cache follows the robot, not the whole map.
  for (auto& t : tiles_) {
    if (t && stamp_ - t->used > kStaleIterations) t.reset();
  }
  if (++stamp_ == 0) {  // wrapped: forget every stamp
    for (auto& t : tiles_) {
      if (t) std::memset(t->cells, 0, sizeof(t->cells));
    }
    stamp_ = 1;
  }
}

std::size_t LookupCache::memoryBytes() const {
  std::size_t b = rows_.capacity() * sizeof(std::int16_t) + tiles_.capacity() * sizeof(void*);
  for (const auto& t : tiles_) {
    if (t) b += sizeof(TileRows);
  }
  return b + (memo_.capacity() + memo_stamp_.capacity() + depth_.capacity()) * 4 + descendants_.capacity() * 8 +
         covered_.capacity() * sizeof(covered_[0]) +
         (slot_nodes_.capacity() + parent_.capacity()) * sizeof(int);
}

// ---------------------------------------------------------------------------------------------------
DpSlamMap::DpSlamMap(double resolution, double entry_prior_cells)
    : resolution_(resolution), prior_distance_(entry_prior_cells * resolution), pool_(new EntryPool) {
  if (!(resolution > 0.0)) throw std::invalid_argument("DpSlamMap: resolution must be > 0");
  if (!(entry_prior_cells > 0.0)) throw std::invalid_argument("DpSlamMap: entry_prior_cells must be > 0");
}

DpSlamMap::~DpSlamMap() = default;

void DpSlamMap::clear() {
  tiles_.clear();
  directory_.clear();
  tx0_ = ty0_ = ntx_ = nty_ = 0;
  pool_.reset(new EntryPool);
  owned_.clear();
  entries_ = 0;
  observed_cells_ = 0;
  root_ = -1;
}

void DpSlamMap::setFreeSaturation(double distance) {
  if (!(distance >= 0.0)) throw std::invalid_argument("DpSlamMap: free saturation must be >= 0");
  free_saturation_ = distance > 0.0 ? static_cast<float>(distance) : std::numeric_limits<float>::infinity();
}

int DpSlamMap::tileId(int ix, int iy) const {
  const int tx = (ix >> kTileShift) - tx0_, ty = (iy >> kTileShift) - ty0_;
  if (tx < 0 || ty < 0 || tx >= ntx_ || ty >= nty_) return -1;
  return directory_[static_cast<std::size_t>(ty) * ntx_ + tx];
}

int DpSlamMap::ensureTile(int ix, int iy) {
  const int id = tileId(ix, iy);
  if (id >= 0) return id;
  const int tx = ix >> kTileShift, ty = iy >> kTileShift;
  if (tx < tx0_ || ty < ty0_ || tx >= tx0_ + ntx_ || ty >= ty0_ + nty_) {
    // Grow the directory with a margin, so that it is rebuilt rarely.
    constexpr int kMargin = 8;
    int nx0 = tx0_, ny0 = ty0_, nx1 = tx0_ + ntx_, ny1 = ty0_ + nty_;
    if (ntx_ == 0) {
      nx0 = tx - kMargin;
      ny0 = ty - kMargin;
      nx1 = tx + kMargin + 1;
      ny1 = ty + kMargin + 1;
    } else {
      if (tx < nx0) nx0 = tx - kMargin;
      if (ty < ny0) ny0 = ty - kMargin;
      if (tx >= nx1) nx1 = tx + kMargin + 1;
      if (ty >= ny1) ny1 = ty + kMargin + 1;
    }
    std::vector<std::int32_t> dir(static_cast<std::size_t>(nx1 - nx0) * (ny1 - ny0), -1);
    for (int y = 0; y < nty_; ++y) {
      for (int x = 0; x < ntx_; ++x) {
        dir[static_cast<std::size_t>(y + ty0_ - ny0) * (nx1 - nx0) + (x + tx0_ - nx0)] =
            directory_[static_cast<std::size_t>(y) * ntx_ + x];
      }
    }
    directory_.swap(dir);
    tx0_ = nx0;
    ty0_ = ny0;
    ntx_ = nx1 - nx0;
    nty_ = ny1 - ny0;
  }
  const int nid = static_cast<int>(tiles_.size());
  tiles_.emplace_back(new Tile);
  tiles_.back()->tx = tx;
  tiles_.back()->ty = ty;
  directory_[static_cast<std::size_t>(ty - ty0_) * ntx_ + (tx - tx0_)] = nid;
  return nid;
}

MapEntry* DpSlamMap::entriesOf(const Cell& c) const { return c.size ? c.entries : nullptr; }

void DpSlamMap::setBlock(Cell& c, int cls, std::uint32_t block) {
  c.cls = static_cast<std::uint8_t>(cls);
  c.block = block;
  c.entries = pool_->at(cls, block);
}

const MapEntry* DpSlamMap::cellEntries(int ix, int iy, int* n) const {
  const int t = tileId(ix, iy);
  if (t < 0) {
    *n = 0;
    return nullptr;
  }
  const Cell& c = tiles_[t]->cells[cellInTile(ix, iy)];
  *n = c.size;
  return entriesOf(c);
}

std::size_t DpSlamMap::memoryBytes() const {
  std::size_t b = tiles_.size() * sizeof(Tile) + tiles_.capacity() * sizeof(void*) +
                  directory_.capacity() * sizeof(std::int32_t) + pool_->bytes();
  for (const auto& l : owned_) b += sizeof(l) + l.capacity() * sizeof(EntryRef);
  return b;
}

bool DpSlamMap::bounds(int* x0, int* y0, int* x1, int* y1) const {
  if (tiles_.empty()) return false;
  int a = tiles_[0]->tx, b = tiles_[0]->ty, c = a, d = b;
  for (const auto& t : tiles_) {
    a = std::min(a, t->tx);
    b = std::min(b, t->ty);
    c = std::max(c, t->tx);
    d = std::max(d, t->ty);
  }
  *x0 = a * kTileSize;
  *y0 = b * kTileSize;
  *x1 = (c + 1) * kTileSize - 1;
  *y1 = (d + 1) * kTileSize - 1;
  return true;
}

// --- Entries ---------------------------------------------------------------------------------------
void DpSlamMap::moveToClass(Cell& c, int cls) {
  const std::uint32_t nb = pool_->allocate(cls);
  std::memcpy(static_cast<void*>(pool_->at(cls, nb)), c.entries, sizeof(MapEntry) * c.size);
  pool_->release(c.cls, c.block);
  setBlock(c, cls, nb);
}

int DpSlamMap::appendEntry(int tile, int cell, const MapEntry& e) {
  Cell& c = tiles_[tile]->cells[cell];
  if (c.size == 0) {
    if (c.cls == 0xFF) setBlock(c, 0, pool_->allocate(0));
    ++observed_cells_;
  } else if (c.size == EntryPool::capacity(c.cls)) {
    moveToClass(c, c.cls + 1);
  }
  if (c.size == 0xFFFF) throw std::length_error("DpSlamMap: too many entries in one cell");
  new (&c.entries[c.size]) MapEntry(e);  // the pool hands out raw pages
  ++entries_;
  const int slot = c.size++;
  if (e.owner == root_ || slot == 0) {
    refreshFree(tile, cell);
  } else {
    lowerFree(*tiles_[tile], cell, freeBits(e));  // an entry more can clear the bits, not set them
  }
  return slot;
}

std::uint8_t DpSlamMap::freeBits(const MapEntry& e) const {
  if (e.hits != 0.0f) return 0;
  return e.distance >= free_saturation_ ? (kFreeForAll | kSaturated) : kFreeForAll;
}

void DpSlamMap::lowerFree(Tile& t, int cell, std::uint8_t bits) {
  const std::uint8_t keep = bits | kCovered;
  if (!(t.free[cell] & ~keep)) return;  // nothing drops (most written cells have no bits)
  t.free[cell] &= keep;
  t.block_free[blockOf(cell)] &= t.free[cell];
}

void DpSlamMap::refreshFree(int tile, int cell) {
  Tile& t = *tiles_[tile];
  const Cell& c = t.cells[cell];
  const int b = blockOf(cell);
  const std::uint8_t covered = t.free[cell] & kCovered;
  t.free[cell] = covered;
  t.block_free[b] = 0;
  if (root_ < 0) return;  // no root told: no bits, every trace looks every cell up
  // Every slot sees some entry (the root's, or kCovered) and whichever it sees has no hit (and is saturated).
  std::uint8_t f = kFreeForAll | kSaturated;
  bool seen = covered != 0;
  for (int j = 0; j < c.size && f; ++j) {
    f &= freeBits(c.entries[j]);
    seen = seen || c.entries[j].owner == root_;
  }
  if (!seen || !f) return;
  t.free[cell] |= f;
  // The block's bits: those all its cells share (its rows are kBlockCells bytes apart by kTileSize).
  const int first = (cell & ~(kTileSize * (kBlockCells - 1) + kBlockCells - 1));
  std::uint8_t all = kFreeForAll | kSaturated;
  for (int y = 0; y < kBlockCells && all; ++y) {
    for (int x = 0; x < kBlockCells; ++x) all &= t.free[first + y * kTileSize + x];
  }
  t.block_free[b] = all;
}

void DpSlamMap::removeFromCell(int tile, int cell, int slot) {
  Cell& c = tiles_[tile]->cells[cell];
  MapEntry* e = c.entries;
  const int last = c.size - 1;
  if (slot != last) {
    e[slot] = e[last];
    owned_[e[slot].owner][e[slot].back].slot = static_cast<std::uint16_t>(slot);
  }
  --c.size;
  --entries_;
  if (c.size == 0) {
    pool_->release(c.cls, c.block);
    c.cls = 0xFF;
    c.block = 0;
    c.entries = nullptr;
    --observed_cells_;
  } else if (c.size == 1 && c.cls > 0) {
    moveToClass(c, 0);  // the usual end of a cell's branches: only the root's entry is left
  } else if (c.cls > 0 && c.size <= EntryPool::capacity(c.cls - 1) / 2) {
    moveToClass(c, c.cls - 1);
  }
  // One entry less can only set the bits: recomputed when that is cheap (a cell's branches end in one entry).
  if (c.size <= kFreeRescanSize) refreshFree(tile, cell);
}

void DpSlamMap::removeFromOwner(int owner, std::uint32_t back) {
  auto& list = owned_[owner];
  const std::size_t last = list.size() - 1;
  if (back != last) {
    list[back] = list[last];
    const EntryRef& r = list[back];
    tiles_[r.tile]->cells[r.cell].entries[r.slot].back = back;
  }
  list.pop_back();
}

void DpSlamMap::deleteNode(int id) {
  if (id < 0 || id >= static_cast<int>(owned_.size())) return;
  auto& list = owned_[id];
  for (const EntryRef& r : list) removeFromCell(r.tile, r.cell, r.slot);
  std::vector<EntryRef>().swap(list);  // free the storage
  compactPool();
}

void DpSlamMap::compactPool() {
  for (int cls = 0; cls < EntryPool::kClasses; ++cls) {
    if (!pool_->wantsCompaction(cls)) continue;
    pool_->compact(cls, [&](std::uint32_t, std::uint32_t to) {
      // A live block's first entry names its cell through the owner's list.
      const MapEntry& e = *pool_->at(cls, to);
      const EntryRef& r = owned_[e.owner][e.back];
      setBlock(tiles_[r.tile]->cells[r.cell], cls, to);
    });
  }
}

void DpSlamMap::mergeChildIntoParent(int child, int parent) {
  requireNodeId(parent);
  const int need = std::max(child, parent) + 1;
  if (static_cast<int>(owned_.size()) < need) owned_.resize(need);
  auto& cl = owned_[child];
  auto& pl = owned_[parent];
  constexpr std::uint16_t kDead = 0xFFFF;
  for (std::size_t i = 0; i < cl.size(); ++i) {
    const int tile = cl[i].tile, cell = cl[i].cell;
    Cell& c = tiles_[tile]->cells[cell];
    MapEntry* e = c.entries;
    int dup = -1;
    for (int j = 0; j < c.size; ++j) {
      if (e[j].owner == parent) {
        dup = j;
        break;
      }
    }
    if (dup >= 0) {
      if (e[dup].distance > e[cl[i].slot].distance) {
        // The parent's entry has seen more: it is the newer one; the child's goes.
        removeFromCell(tile, cell, cl[i].slot);
        cl[i].slot = kDead;
        continue;
      }
      removeFromOwner(parent, e[dup].back);
      removeFromCell(tile, cell, dup);  // may move the child's entry: cl[i].slot follows
    }
    MapEntry& me = c.entries[cl[i].slot];
    me.owner = static_cast<std::int16_t>(parent);
    me.back = static_cast<std::uint32_t>(pl.size());
    pl.push_back(cl[i]);
    if (parent == root_) refreshFree(tile, cell);
  }
  std::vector<EntryRef>().swap(cl);
  compactPool();
}

// --- Lookups ---------------------------------------------------------------------------------------
const MapEntry* DpSlamMap::lookup(int ix, int iy, int node, const AncestryTree& tree) const {
  int n = 0;
  const MapEntry* e = cellEntries(ix, iy, &n);
  if (n == 0) return nullptr;
  for (int a = node; a >= 0; a = tree.parent(a)) {
    for (int j = 0; j < n; ++j) {
      if (e[j].owner == a) return &e[j];
    }
  }
  return nullptr;
}

std::vector<int> DpSlamMap::lineageRank(const AncestryTree& tree, int node) {
  std::vector<int> rank(tree.idCapacity(), -1);
  int r = 0;
  for (int a = node; a >= 0; a = tree.parent(a)) rank[a] = r++;
  return rank;
}

const MapEntry* DpSlamMap::lookup(int ix, int iy, const std::vector<int>& rank) const {
  int n = 0;
  const MapEntry* e = cellEntries(ix, iy, &n);
  const MapEntry* best = nullptr;
  int best_rank = 0;
  for (int j = 0; j < n; ++j) {
    const int o = e[j].owner;
    const int r = o < static_cast<int>(rank.size()) ? rank[o] : -1;
    if (r >= 0 && (!best || r < best_rank)) {
      best = &e[j];
      best_rank = r;
    }
  }
  return best;
}

namespace {
/// Unit vectors of the 255 quantised normal angles (index 0 unused).
struct NormalTable {
  double c[256], s[256];
  NormalTable() {
    c[0] = s[0] = 0.0;
    for (int k = 1; k < 256; ++k) {
      const double a = (k - 0.5) * M_PI / 255.0;
      c[k] = std::cos(a);
      s[k] = std::sin(a);
    }
  }
};
const NormalTable& normalTable() {
  static const NormalTable t;
  return t;
}

constexpr std::uint32_t kUniform = 0x80000000u;  ///< row word flag: every slot sees entry (word & ~flag) − 1
}  // namespace

void DpSlamMap::buildRow(int tile, int cell, LookupCache& cache) const {
  const Cell& c = tiles_[tile]->cells[cell];
  const std::size_t slots = cache.slot_nodes_.size();
  cache.scratch_.resize(slots);
  std::int16_t* out = cache.scratch_.data();
  if (cache.slot_masks_) {
    rowFromMasks(c, cache, out);
  } else {
    rowFromWalks(c, cache, out);
  }
  bool uniform = true;
  for (std::size_t s = 1; s < slots && uniform; ++s) uniform = out[s] == out[0];
  if (cache.every_particle_ && slots > 0) {
    bool covered = true;
    for (std::size_t s = 0; s < slots && covered; ++s) covered = out[s] >= 0;
    if (covered) cache.covered_.emplace_back(tile, cell);
  }
  LookupCache::TileRows& tr = *cache.tiles_[tile];
  tr.cells[cell].stamp = cache.stamp_;
  if (uniform && slots > 0) {
    tr.cells[cell].row = kUniform | static_cast<std::uint32_t>(out[0] + 1);
  } else {
    tr.cells[cell].row = static_cast<std::uint32_t>(cache.rows_.size() / (slots ? slots : 1));
    cache.rows_.insert(cache.rows_.end(), out, out + slots);
  }
}

void DpSlamMap::rowFromMasks(const Cell& c, const LookupCache& cache, std::int16_t* out) const {
  const MapEntry* e = entriesOf(c);
  const std::size_t slots = cache.slot_nodes_.size();
  std::int32_t best_depth[64];
  for (std::size_t s = 0; s < slots; ++s) {
    out[s] = -1;
    best_depth[s] = -1;
  }
  // Each entry claims the slots that descend from its owner; the deepest owner, the nearest ancestor, wins.
  for (int j = 0; j < c.size; ++j) {
    const int o = e[j].owner;
    if (o >= static_cast<int>(cache.descendants_.size())) continue;
    const std::int32_t d = cache.depth_[o];
    for (std::uint64_t m = cache.descendants_[o]; m; m &= m - 1) {
      const int s = __builtin_ctzll(m);
      if (d > best_depth[s]) {
        best_depth[s] = d;
        out[s] = static_cast<std::int16_t>(j);
      }
    }
  }
}

void DpSlamMap::rowFromWalks(const Cell& c, LookupCache& cache, std::int16_t* out) const {
  const MapEntry* e = entriesOf(c);
  const std::size_t slots = cache.slot_nodes_.size();
  if (++cache.memo_counter_ == 0) {  // wrapped
    std::fill(cache.memo_stamp_.begin(), cache.memo_stamp_.end(), 0u);
    cache.memo_counter_ = 1;
  }
  const std::uint32_t mark = cache.memo_counter_;
  for (int j = 0; j < c.size; ++j) {
    const int o = e[j].owner;
    if (o < static_cast<int>(cache.memo_.size())) {
      cache.memo_[o] = j;
      cache.memo_stamp_[o] = mark;
    }
  }
  int stack[64];
  std::vector<int> big_stack;
  for (std::size_t s = 0; s < slots; ++s) {
    int n = cache.slot_nodes_[s];
    int depth = 0;
    big_stack.clear();
    while (n >= 0 && cache.memo_stamp_[n] != mark) {
      if (depth < 64) {
        stack[depth] = n;
      } else {
        big_stack.push_back(n);
      }
      ++depth;
      n = cache.parent_[n];
    }
    const int value = n < 0 ? -1 : cache.memo_[n];
    for (int k = 0; k < depth; ++k) {
      const int x = k < 64 ? stack[k] : big_stack[k - 64];
      cache.memo_[x] = value;
      cache.memo_stamp_[x] = mark;
    }
    out[s] = static_cast<std::int16_t>(cache.memo_[cache.slot_nodes_[s]]);
  }
}

void DpSlamMap::setRowSlot(LookupCache& cache, int tile, int cell, int slot, int value) {
  if (static_cast<std::size_t>(tile) >= cache.tiles_.size() || !cache.tiles_[tile]) return;
  LookupCache::TileRows& tr = *cache.tiles_[tile];
  if (tr.cells[cell].stamp != cache.stamp_) return;  // no row yet: it will be built from the map
  const std::size_t slots = cache.slot_nodes_.size();
  std::uint32_t word = tr.cells[cell].row;
  if (word & kUniform) {  // materialise the row
    const auto v = static_cast<std::int16_t>(static_cast<std::int32_t>(word & ~kUniform) - 1);
    word = static_cast<std::uint32_t>(cache.rows_.size() / (slots ? slots : 1));
    cache.rows_.insert(cache.rows_.end(), slots, v);
    tr.cells[cell].row = word;
  }
  cache.rows_[static_cast<std::size_t>(word) * slots + slot] = static_cast<std::int16_t>(value);
}

inline bool DpSlamMap::seek(Cursor& cur, int ix, int iy, LookupCache& cache) const {
  const int tx = ix >> kTileShift, ty = iy >> kTileShift;
  if (tx == cur.tx && ty == cur.ty) return cur.tile >= 0;
  cur.tx = tx;
  cur.ty = ty;
  cur.tile = tileId(ix, iy);
  if (cur.tile < 0) return false;
  cur.t = tiles_[cur.tile].get();
  if (static_cast<std::size_t>(cur.tile) >= cache.tiles_.size()) cache.tiles_.resize(tiles_.size());
  auto& tr = cache.tiles_[cur.tile];
  if (!tr) tr.reset(new LookupCache::TileRows());
  tr->used = cache.stamp_;
  cur.rows = tr.get();
  return true;
}

inline bool DpSlamMap::seek(Cursor& cur, int ix, int iy, LookupCache& cache, bool create) {
  const int tx = ix >> kTileShift, ty = iy >> kTileShift;
  if (tx == cur.tx && ty == cur.ty && cur.tile >= 0) return true;
  if (create) {
    ensureTile(ix, iy);
    cur.tx = std::numeric_limits<int>::min();
  }
  return static_cast<const DpSlamMap*>(this)->seek(cur, ix, iy, cache);
}

inline MapEntry* DpSlamMap::resolve(const Cursor& cur, int cell, int slot, LookupCache& cache) const {
  const Cell& c = cur.t->cells[cell];
  if (c.size == 0) return nullptr;
  MapEntry* e = c.entries;
  if (c.size == 1 && e->owner == cache.root_) return e;  // seen by everyone
  const auto& rc = static_cast<const LookupCache::TileRows*>(cur.rows)->cells[cell];
  if (rc.stamp != cache.stamp_) buildRow(cur.tile, cell, cache);
  const std::uint32_t word = rc.row;
  const int j = (word & kUniform) ? static_cast<int>(word & ~kUniform) - 1
                                  : cache.rows_[static_cast<std::size_t>(word) * cache.slot_nodes_.size() + slot];
  return j < 0 ? nullptr : e + j;
}

const MapEntry* DpSlamMap::visibleCached(int tile, int cell, int slot, LookupCache& cache) const {
  Cursor cur;
  const Tile& t = *tiles_[tile];
  if (!seek(cur, t.tx << kTileShift, t.ty << kTileShift, cache)) return nullptr;
  return resolve(cur, cell, slot, cache);
}

const MapEntry* DpSlamMap::cachedLookup(int ix, int iy, int slot, LookupCache& cache) const {
  const int t = tileId(ix, iy);
  if (t < 0) return nullptr;
  return visibleCached(t, cellInTile(ix, iy), slot, cache);
}

int DpSlamMap::quantizeNormal(double nx, double ny) {
  if (nx == 0.0 && ny == 0.0) return 0;
  return quantizeNormalAngle(std::atan2(ny, nx));
}

int DpSlamMap::quantizeNormalAngle(double a) {
  if (std::isnan(a)) return 0;
  // A normal's sign does not matter: angle modulo π. Angles within ±2π (a scan's normal plus a heading)
  // take a subtraction, exact there as fmod is (Sterbenz), instead of fmod's library call.
  if (!(std::abs(a) < M_PI)) a = std::abs(a) < 2.0 * M_PI ? a - std::copysign(M_PI, a) : std::fmod(a, M_PI);
  if (a < 0.0) a += M_PI;
  if (a >= M_PI) a -= M_PI;
  return std::min(255, 1 + static_cast<int>(a * (255.0 / M_PI)));
}

namespace {
/// std::round (halves away from zero) without the library call where |x| < 2^52: the truncation and the
/// fraction x − trunc(x) are exact there.
double roundHalfAway(double x) {
  if (!(std::abs(x) < 0x1p52)) return std::round(x);
  const double t = static_cast<double>(static_cast<long long>(x));
  const double f = x - t;
  return f >= 0.5 ? t + 1.0 : (f <= -0.5 ? t - 1.0 : t);
}
}  // namespace

int DpSlamMap::quantizeOffset(double s) const {
  const double k = roundHalfAway(s * (127.0 / (0.75 * resolution_))) + 128.0;
  return static_cast<int>(std::min(255.0, std::max(1.0, k)));
}

inline double DpSlamMap::stopPoint(int ix, int iy, int q, int k, const MapBeam& b, double t0, double t1) const {
  if (q && k) {
    const NormalTable& n = normalTable();
    const double cd = n.c[q] * b.dx + n.s[q] * b.dy;
    if (std::abs(cd) > 1e-6) {
      // n·(o + t·dir − centre) = offset
      const double cx = (ix + 0.5) * resolution_ - b.ox, cy = (iy + 0.5) * resolution_ - b.oy;
      const double t = (offsetValue(k) + n.c[q] * cx + n.s[q] * cy) / cd;
      return std::min(t1, std::max(t0, t));
    }
  }
  return 0.5 * (t0 + t1);
}

std::uint8_t DpSlamMap::meanOffset(int old_q, int old_k, double old_hits, int new_q, int hit_offset) const {
  if (!new_q || !hit_offset) return static_cast<std::uint8_t>(old_k);
  if (!(old_hits > 0.0)) return static_cast<std::uint8_t>(hit_offset);
  double s_old = 0.0;
  if (old_q && old_k) {
    // The old surface line's point nearest the centre, measured along the new normal.
    const NormalTable& n = normalTable();
    s_old = offsetValue(old_k) * (n.c[old_q] * n.c[new_q] + n.s[old_q] * n.s[new_q]);
  }
  const double s = s_old + (offsetValue(hit_offset) - s_old) / (old_hits + 1.0);
  return static_cast<std::uint8_t>(quantizeOffset(s));
}

inline double DpSlamMap::chordFactor(int q, const MapBeam& b, bool near_return) const {
  if (q) {
    const NormalTable& n = normalTable();
    return std::max(cell_normal_min_cos_, std::abs(n.c[q] * b.dx + n.s[q] * b.dy));
  }
  return near_return ? b.incidence : 1.0;
}

// --- Updates ---------------------------------------------------------------------------------------
namespace {
struct Observation {
  float d;
  float hit;
};
}  // namespace

void DpSlamMap::observe(int ix, int iy, int node, const AncestryTree& tree, double d, bool hit) {
  requireNodeId(node);
  const int tile = ensureTile(ix, iy);
  const int cell = cellInTile(ix, iy);
  const MapEntry* vis = lookup(ix, iy, node, tree);
  if (static_cast<int>(owned_.size()) <= node) owned_.resize(node + 1);
  if (vis && vis->owner == node) {
    MapEntry* m = const_cast<MapEntry*>(vis);
    m->hits += hit ? 1.0f : 0.0f;
    m->distance += static_cast<float>(d);
    refreshFree(tile, cell);
    return;
  }
  MapEntry ne;
  ne.owner = static_cast<std::int16_t>(node);
  ne.hits = (vis ? vis->hits : 0.0f) + (hit ? 1.0f : 0.0f);
  ne.distance = vis ? vis->distance + static_cast<float>(d) : static_cast<float>(d + prior_distance_);
  ne.back = static_cast<std::uint32_t>(owned_[node].size());
  const int s = appendEntry(tile, cell, ne);
  owned_[node].push_back({static_cast<std::uint32_t>(tile), static_cast<std::uint16_t>(cell), static_cast<std::uint16_t>(s)});
}

void DpSlamMap::planBeam(const MapBeam& b, double max_range, int slot, LookupCache& cache, std::vector<CellWrite>& out,
                         bool only_unknown) const {
  // A cell flagged so is seen the same by every slot: saturated free (left out unless it holds the return),
  // or known at all (left out by only_unknown).
  const std::uint8_t skip_flag = only_unknown ? kFreeForAll : kSaturated;
  const bool hit = !b.no_return && b.range <= max_range;
  const double length = std::min(b.range, max_range);
  // Near the surface hit, distance counts along its normal (setSurfaceDepth).
  const double surface_from = hit && surface_depth_ > 0.0 ? length - surface_depth_ : length + 1.0;
  // setCellNormals: the cell the beam stops in takes the normal of the surface it hit.
  const bool normals = cell_normal_min_cos_ > 0.0;
  const int beam_normal = normals && hit ? quantizeNormalAngle(b.normal_angle) : 0;
  const double near_end = hit ? length - 2.0 * resolution_ : length;  // every beam writes its last two cells
  const double from = std::max(0.0, std::min(b.write_from, near_end));
  Cursor cur;
  traceCells(b.ox, b.oy, b.dx, b.dy, from, length, resolution_, [&](int ix, int iy, double t0, double t1) -> int {
    const bool end = hit && t1 >= length;
    int q = 0;  // the cell's normal, if it has statistics
    if ((normals || !end || only_unknown) && seek(cur, ix, iy, cache)) {
      const int cell = cellInTile(ix, iy);
      if ((!end || only_unknown) && (cur.t->free[cell] & skip_flag)) return passFree(*cur.t, cell, skip_flag);
      const MapEntry* v = resolve(cur, cell, slot, cache);
      if (v && only_unknown) return kTraceNext;
      if (v) {
        if (!end && (freeBits(*v) & kSaturated)) return kTraceNext;
        if (normals) q = v->normal;
      }
    }
    if (end && !q) q = beam_normal;  // a new surface cell: the normal it is about to take
    // Filled in place: a CellWrite built on the stack and copied in stalls on store forwarding.
    out.emplace_back();
    CellWrite& w = out.back();
    w.ix = ix;
    w.iy = iy;
    w.d = static_cast<float>((t1 - t0) * chordFactor(q, b, t1 >= surface_from));
    w.hit = end ? 1 : 0;
    if (end) {
      w.normal = static_cast<std::uint8_t>(beam_normal);
      const int nq = beam_normal ? beam_normal : q;  // the normal the entry has after this write
      if (surface_offsets_ && nq) {
        const NormalTable& n = normalTable();
        const double px = b.ox + b.dx * length - (ix + 0.5) * resolution_;
        const double py = b.oy + b.dy * length - (iy + 0.5) * resolution_;
        w.offset = static_cast<std::uint8_t>(quantizeOffset(n.c[nq] * px + n.s[nq] * py));
      }
    }
    return kTraceNext;
  });
}

void DpSlamMap::applyWrites(const std::vector<CellWrite>& writes, int slot, int node, LookupCache& cache) {
  requireNodeId(node);
  if (static_cast<int>(owned_.size()) <= node) owned_.resize(node + 1);
  Cursor cur;
  for (const CellWrite& w : writes) {
    seek(cur, w.ix, w.iy, cache, true);
    const int cell = cellInTile(w.ix, w.iy);
    MapEntry* vis = resolve(cur, cell, slot, cache);
    MapEntry ne;
    ne.owner = static_cast<std::int16_t>(node);
    ne.normal = w.normal;
    ne.offset = w.offset;
    if (vis) {
      MapEntry& v = *vis;
      if (w.hit == 0 && (freeBits(v) & kSaturated)) continue;
      const int nq = w.normal ? w.normal : v.normal;
      const std::uint8_t offset = w.offset ? meanOffset(v.normal, v.offset, v.hits, nq, w.offset) : v.offset;
      if (v.owner == node) {
        v.hits += w.hit;
        v.distance += w.d;
        if (w.normal) v.normal = w.normal;
        v.offset = offset;
        if (node == root_) {
          refreshFree(cur.tile, cell);
        } else {
          lowerFree(*cur.t, cell, freeBits(v));
        }
        continue;
      }
      ne.hits = v.hits + w.hit;
      ne.distance = v.distance + w.d;
      if (!w.normal) ne.normal = v.normal;  // the copy keeps what the lineage saw
      ne.offset = offset;
    } else {
      ne.hits = w.hit;
      ne.distance = w.d + static_cast<float>(prior_distance_);
    }
    ne.back = static_cast<std::uint32_t>(owned_[node].size());
    const int s = appendEntry(cur.tile, cell, ne);
    owned_[node].push_back({static_cast<std::uint32_t>(cur.tile), static_cast<std::uint16_t>(cell), static_cast<std::uint16_t>(s)});
    // Keep this slot's cached view in step (other slots cannot see the new entry: it is a leaf's).
    setRowSlot(cache, cur.tile, cell, slot, s);
  }
  // With a cache begun for every particle, a row built in which each slot sees an entry marks the cell
  // kCovered (after the writes, which its bits then include). No root told: no bits at all.
  for (const auto& tc : cache.covered_) {
    Tile& t = *tiles_[tc.first];
    if (root_ < 0 || (t.free[tc.second] & kCovered)) continue;
    t.free[tc.second] |= kCovered;
    refreshFree(tc.first, tc.second);
  }
  cache.covered_.clear();
}

void DpSlamMap::addBeam(const MapBeam& b, double max_range, int slot, int node, LookupCache& cache) {
  std::vector<CellWrite> writes;
  planBeam(b, max_range, slot, cache, writes);
  applyWrites(writes, slot, node, cache);
}

// --- Observation model -----------------------------------------------------------------------------
double DpSlamMap::beamLogLikelihood(const MapBeam& b, double max_range, int slot, LookupCache& cache,
                                    const BeamModelConfig& m) const {
  const bool no_return = b.no_return || b.range >= max_range;
  const double z = std::min(b.range, max_range);
  const double t_end = no_return ? z : std::min(z + m.window, max_range);
  const double window_start = z - m.window;
  const double inv_2s2 = 0.5 / (m.sigma * m.sigma);
  const double mu_unknown = 1.0 / m.unknown_mean_free_path;
  const double surface = no_return ? 0.0 : surface_depth_;  // setSurfaceDepth: |t - z| < this counts along the normal
  const bool normals = cell_normal_min_cos_ > 0.0;
  const bool offsets = normals && surface_offsets_;
  double tau = 0.0, reach = 1.0, eval = 0.0;
  bool in_window = false;
  Cursor cur;
  traceCells(b.ox, b.oy, b.dx, b.dy, 0.0, t_end, resolution_, [&](int ix, int iy, double t0, double t1) -> int {
    double mu = mu_unknown;
    int q = 0, k = 0;
    if (seek(cur, ix, iy, cache)) {
      const int cell = cellInTile(ix, iy);
      // density 0 for every slot: adds nothing
      if (cur.t->free[cell] & kFreeForAll) return passFree(*cur.t, cell, kFreeForAll);
      if (const MapEntry* v = resolve(cur, cell, slot, cache)) {
        mu = v->density();
        if (normals) q = v->normal;
        if (offsets) k = v->offset;
      }
    }
    if (mu == 0.0) return kTraceNext;
    double d = (t1 - t0) * chordFactor(q, b, std::abs(0.5 * (t0 + t1) - z) < surface);
    if (t1 < window_start) {
      tau += mu * d;
      return kTraceNext;
    }
    if (!in_window) {
      reach = negExp(tau);
      in_window = true;
    }
    const double pass = negExp(mu * d);
    const double stop = reach * (1.0 - pass);
    reach *= pass;
    const double e = stopPoint(ix, iy, q, k, b, t0, t1) - z;
    if (std::abs(e) < m.window) eval += stop * negExp(e * e * inv_2s2);
    return reach > 1e-9 ? kTraceNext : kTraceStop;  // nothing left to explain: stop tracing
  });
  if (!in_window) reach = negExp(tau);
  const double value = no_return ? eval + reach : (reach < 1.0 ? eval / (1.0 - reach) : 0.0);
  return value > 0.0 ? std::max(std::log(value), m.log_floor) : m.log_floor;
}

double DpSlamMap::beamEndpointLogLikelihood(const MapBeam& b, double half_window, int slot, LookupCache& cache,
                                            const BeamModelConfig& m) const {
  if (b.no_return) return 0.0;
  const double z = b.range;
  const double inv_2s2 = 0.5 / (m.sigma * m.sigma);
  const double mu_unknown = 1.0 / m.unknown_mean_free_path;
  double reach = 1.0, eval = 0.0;
  Cursor cur;
  traceCells(b.ox, b.oy, b.dx, b.dy, std::max(0.0, z - half_window), z + half_window, resolution_,
             [&](int ix, int iy, double t0, double t1) -> int {
               double mu = mu_unknown;
               int q = 0, k = 0;
               if (seek(cur, ix, iy, cache)) {
                 const int cell = cellInTile(ix, iy);
                 // density 0 for every slot (no block skips: the window is a few cells long)
                 if (cur.t->free[cell] & kFreeForAll) return kTraceNext;
                 if (const MapEntry* v = resolve(cur, cell, slot, cache)) {
                   mu = v->density();
                   if (cell_normal_min_cos_ > 0.0) {
                     q = v->normal;
                     if (surface_offsets_) k = v->offset;
                   }
                 }
               }
               if (mu == 0.0) return kTraceNext;
               const double d = (t1 - t0) * chordFactor(q, b, std::abs(0.5 * (t0 + t1) - z) < surface_depth_);
               const double pass = negExp(mu * d);
               const double stop = reach * (1.0 - pass);
               reach *= pass;
               const double e = stopPoint(ix, iy, q, k, b, t0, t1) - z;
               eval += stop * negExp(e * e * inv_2s2);
               return reach > 1e-9 ? kTraceNext : kTraceStop;
             });
  const double value = reach < 1.0 ? eval / (1.0 - reach) : 0.0;
  return value > 0.0 ? std::max(std::log(value), m.log_floor) : m.log_floor;
}

// --- Consistency -----------------------------------------------------------------------------------
std::string DpSlamMap::check() const {
  std::size_t count = 0, cells = 0;
  for (std::size_t t = 0; t < tiles_.size(); ++t) {
    for (int ci = 0; ci < kTileSize * kTileSize; ++ci) {
      const Cell& c = tiles_[t]->cells[ci];
      if (c.size == 0) continue;
      ++cells;
      const MapEntry* e = entriesOf(c);
      for (int j = 0; j < c.size; ++j) {
        ++count;
        const int o = e[j].owner;
        if (o < 0 || o >= static_cast<int>(owned_.size()) || e[j].back >= owned_[o].size()) {
          return "entry with a bad owner/back-index in tile " + std::to_string(t);
        }
        const EntryRef& r = owned_[o][e[j].back];
        if (r.tile != t || r.cell != ci || r.slot != j) return "back-reference mismatch for owner " + std::to_string(o);
        for (int k = j + 1; k < c.size; ++k) {
          if (e[k].owner == o) return "two entries of owner " + std::to_string(o) + " in one cell";
        }
      }
    }
  }
  std::size_t listed = 0;
  for (const auto& l : owned_) listed += l.size();
  if (count != entries_) return "entry counter mismatch";
  if (cells != observed_cells_) return "observed cell counter mismatch";
  if (listed != entries_) return "owner lists hold " + std::to_string(listed) + " refs for " + std::to_string(count) + " entries";
  return std::string();
}

}  // namespace laser_dpslam
