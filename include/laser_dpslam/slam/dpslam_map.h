// DP-SLAM's shared map (Eliazar & Parr, DP-SLAM 2.0 laser-penetration map). One grid for all particles:
// a cell holds a small array of entries, one per ancestry node that observed it, each a full copy of
// that lineage's statistics {hits, distance} (density = hits / distance). The grid is tiled and grows on
// demand. Includes the exact beam traversal (Amanatides–Woo with chord lengths), the per-iteration lookup
// cache and the penetration observation model with a per-beam floor. No ROS.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "laser_dpslam/slam/ancestry_tree.h"

namespace laser_dpslam {

/// One lineage's statistics in one cell.
struct MapEntry {
  std::int16_t owner = -1;  ///< ancestry node ID (below kMaxNodeId: 16 bits keep the entry at 16 bytes)
  std::uint8_t normal = 0;  ///< quantised normal of the surface the lineage saw here, see setCellNormals (0 = none)
  std::uint8_t offset = 0;  ///< quantised position of that surface along the normal, see setSurfaceOffsets (0 = none)
  float hits = 0.0f;        ///< beams that stopped in the cell (cumulative over the lineage)
  float distance = 0.0f;    ///< m of beam travelled through the cell (cumulative, plus the prior)
  std::uint32_t back = 0;   ///< index of this entry in its owner's entry list

  double density() const { return hits > 0.0f ? static_cast<double>(hits) / distance : 0.0; }  ///< 1/m
};

/// What a traceCells callback returns: stop, go on to the next cell, or skip the rest of the cell's block.
enum TraceStep : int { kTraceStop = 0, kTraceNext = 1, kTraceSkipBlock = 2 };
/// Blocks of (1 << kTraceBlockShift)² cells, aligned on multiples of that size: the unit kTraceSkipBlock skips.
constexpr int kTraceBlockShift = 3;

/// traceCells' skip: moves the traversal state (cell, entry time, next crossings) to the first cell past the
/// block of (ix, iy), exactly as the cell-by-cell steps would (the same additions in the same order, the same
/// tie rule: at equal crossing times the y step comes first). Returns false, changing nothing, when the
/// segment ends inside the block.
inline bool skipBlock(int sx, int sy, double tdx, double tdy, double t_end, int& ix, int& iy, double& t, double& tmx,
                      double& tmy) {
  constexpr int kLast = (1 << kTraceBlockShift) - 1;
  const int bx = ix & ~kLast, by = iy & ~kLast;
  const int nx = sx > 0 ? bx + kLast - ix + 1 : ix - bx + 1;  // x crossings until the block is left in x
  const int ny = sy > 0 ? by + kLast - iy + 1 : iy - by + 1;
  double ex = tmx, ey = tmy;  // the time of the leaving crossing in x, in y
  for (int k = 1; k < nx; ++k) ex += tdx;
  for (int k = 1; k < ny; ++k) ey += tdy;
  if (ex < ey) {  // leaves in x; the y crossings before it stay inside
    if (!(ex < t_end)) return false;
    while (tmy <= ex) {
      iy += sy;
      tmy += tdy;
    }
    ix += sx * nx;
    t = ex;
    tmx = ex + tdx;
  } else {
    if (!(ey < t_end)) return false;
    while (tmx < ey) {
      ix += sx;
      tmx += tdx;
    }
    iy += sy * ny;
    t = ey;
    tmy = ey + tdy;
  }
  return true;
}

/// Exact grid traversal (Amanatides & Woo 1987) of the segment t ∈ [t_begin, t_end] (m) of the ray
/// origin + t·dir (origin in m, dir a unit vector) on a grid of `resolution` m whose cell (ix, iy) covers
/// [ix·res, (ix+1)·res) × [iy·res, (iy+1)·res). Calls f(ix, iy, t0, t1) for every cell the segment crosses,
/// in order, with t0 < t1 the part of the segment inside it (so t1 − t0 is the chord length); stops early
/// when f returns false (kTraceStop). When f returns kTraceSkipBlock, the trace goes on at the first cell
/// past the 8 × 8 block holding this one, without calling f for the block's other cells, provided the
/// segment leaves the block (else it goes on cell by cell to its end). The skip repeats the additions the
/// cell-by-cell steps would make, so the cells and chords after it are the same to the last bit.
template <class F>
inline void traceCells(double ox, double oy, double dx, double dy, double t_begin, double t_end, double resolution,
                       F&& f) {
  if (!(t_end > t_begin)) return;
  const double inv = 1.0 / resolution;
  const double px = (ox + dx * t_begin) * inv, py = (oy + dy * t_begin) * inv;
  // floor as truncation and a correction: the same integers as std::floor in fewer instructions (x86-64
  // before SSE4.1 has no rounding instruction, and a trace is often only a few cells long).
  int ix = static_cast<int>(px), iy = static_cast<int>(py);
  ix -= px < ix;
  iy -= py < iy;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int sx = dx > 0.0 ? 1 : -1, sy = dy > 0.0 ? 1 : -1;
  const double tdx = dx != 0.0 ? resolution / std::abs(dx) : kInf;
  const double tdy = dy != 0.0 ? resolution / std::abs(dy) : kInf;
  double tmx = dx != 0.0 ? t_begin + (dx > 0.0 ? (ix + 1 - px) : (px - ix)) * tdx : kInf;
  double tmy = dy != 0.0 ? t_begin + (dy > 0.0 ? (iy + 1 - py) : (py - iy)) * tdy : kInf;
  double t = t_begin;
  bool may_skip = true;  // false once the segment is known to end inside the current block
  for (;;) {
    const double tn = std::min(std::min(tmx, tmy), t_end);
    if (tn > t) {
      const int r = static_cast<int>(f(ix, iy, t, tn));
      if (r == kTraceStop) return;
      if (r == kTraceSkipBlock && may_skip && skipBlock(sx, sy, tdx, tdy, t_end, ix, iy, t, tmx, tmy)) continue;
      if (r == kTraceSkipBlock) may_skip = false;
    }
    if (tn >= t_end) return;
    if (tmx < tmy) {
      ix += sx;
      t = tmx;
      tmx += tdx;
    } else {
      iy += sy;
      t = tmy;
      tmy += tdy;
    }
  }
}

/// The laser-penetration observation model (DP-SLAM 2.0).
struct BeamModelConfig {
  double sigma = 0.13;             ///< m, standard deviation of the range error (DP-SLAM low level: √0.017)
  double window = 0.5;             ///< m; a stop farther than this from the measured range adds nothing
  double log_floor = -1.15;        ///< minimum log-likelihood of one beam (outliers, dynamic objects)
  double unknown_mean_free_path = 8.0;  ///< m; an unobserved cell stops a beam with density 1/this
};

/// One beam in the map frame, ready to score or to write.
struct MapBeam {
  double ox = 0.0, oy = 0.0;  ///< m, laser position
  double dx = 1.0, dy = 0.0;  ///< unit direction
  double range = 0.0;         ///< m, measured range (for a no-return beam: the tracing cap)
  bool no_return = false;     ///< free space up to `range`, nothing hit
  double incidence = 1.0;     ///< |cos| of the angle to the normal of the surface hit (see setSurfaceDepth)
  /// rad, direction of the normal of the surface hit (modulo π: its sign does not matter); NaN = unknown
  /// (setCellNormals). An angle, not a vector: the scan's angle plus the pose's heading, no atan2 per particle
  double normal_angle = std::numeric_limits<double>::quiet_NaN();
  /// m; planBeam writes from here on (the last two cells before a return always): the free space nearer the
  /// laser is written by beams that start nearer, spaced at most a cell apart
  double write_from = 0.0;
};

class DpSlamMap;

/// Per-iteration lookup cache (one per thread): for the current particles (slots → leaf nodes), the first
/// access to a cell in an iteration resolves every particle's visible entry at once (walk up to the first
/// ancestor already resolved, fill down); later accesses are O(1). Rows live until the next begin().
class LookupCache {
 public:
  LookupCache() = default;
  /// Starts an iteration: `slot_nodes[s]` is the ancestry node whose map slot s sees. Invalidates all rows.
  /// `every_particle`: every particle descends from one of the slot nodes (the writers' nodes, as DpSlam
  /// begins the cache it passes to applyWrites), so that a cell in which each slot sees an entry is seen by
  /// every particle (DpSlamMap's kCovered).
  void begin(const AncestryTree& tree, const std::vector<int>& slot_nodes, bool every_particle = false);
  std::size_t slots() const { return slot_nodes_.size(); }
  std::size_t rowsBuilt() const { return rows_.size() / (slot_nodes_.empty() ? 1 : slot_nodes_.size()); }
  std::size_t memoryBytes() const;

 private:
  friend class DpSlamMap;
  static constexpr int kTileCells = 64 * 64;
  static constexpr std::uint32_t kStaleIterations = 32;  ///< a tile's rows unused this long are freed
  /// A cell's row is valid when its stamp is the iteration's; the two side by side share a cache line.
  struct TileRows {
    struct {
      std::uint32_t stamp;
      std::uint32_t row;
    } cells[kTileCells];
    std::uint32_t used = 0;  ///< the last iteration (stamp) a trace entered the tile
  };
  std::vector<int> slot_nodes_;
  std::vector<int> parent_;  ///< snapshot of the tree's parents, by node ID
  int root_ = -1;
  std::uint32_t stamp_ = 0;
  std::vector<std::unique_ptr<TileRows>> tiles_;  ///< by map tile ID
  /// slots() values per row: entry index or -1. A cell holds one entry per node ID at most, so an
  /// index fits 16 bits (DpSlamMap::kMaxNodeId); the rows are most of a cache's memory.
  std::vector<std::int16_t> rows_;
  bool every_particle_ = false;  ///< begin's every_particle
  /// With every_particle_: the (tile, cell) of the rows built in which every slot sees an entry, until
  /// applyWrites marks them DpSlamMap::kCovered.
  std::vector<std::pair<int, int>> covered_;
  std::vector<std::int16_t> scratch_;
  std::vector<std::int32_t> memo_;                 ///< by node ID, while building a row
  std::vector<std::uint32_t> memo_stamp_;
  std::uint32_t memo_counter_ = 0;
  /// With at most 64 slots, by node ID: the slots whose node is this one or descends from it, and the node's
  /// depth below the root. A row is then built from the cell's entries alone: each entry's owner claims its
  /// slots, the deepest owner (the nearest ancestor) wins.
  std::vector<std::uint64_t> descendants_;
  std::vector<std::int32_t> depth_;
  bool slot_masks_ = false;
};

/// The shared map. Thread safety: const member functions (scoring, lookups) may run concurrently, each
/// thread with its own LookupCache; everything else is single-threaded.
class DpSlamMap : public AncestryHooks {
 public:
  /// `entry_prior_cells`: a new entry for an unobserved cell starts with this many cells' worth of
  /// distance already travelled without a stop (DP-SLAM's L_PRIOR_DIST).
  explicit DpSlamMap(double resolution = 0.05, double entry_prior_cells = 4.0);
  ~DpSlamMap() override;
  DpSlamMap(const DpSlamMap&) = delete;
  DpSlamMap& operator=(const DpSlamMap&) = delete;

  void clear();
  double resolution() const { return resolution_; }
  /// Within `depth` m (along the beam) of a return, a beam's distance through a cell counts multiplied by
  /// the beam's `incidence`, i.e. as depth along the normal of the surface it ends on, in the writes and in
  /// both likelihoods alike. A cell holds stops per metre of *normal* depth, whatever the angle the beams
  /// came from: without it, the stops that range noise spreads in front of a surface (written mostly by
  /// head-on beams, one cell of chord each) stop oblique beams early, which travel 1/cos as far through
  /// them, and the filter prefers poses behind the truth (maps too short, doc/benchmarks.md). 0 = off.
  void setSurfaceDepth(double depth) { surface_depth_ = depth; }
  double surfaceDepth() const { return surface_depth_; }
  /// Cell normals. A cell in which a beam with a known surface normal (MapBeam::nx, ny) stopped remembers
  /// that normal (the last one, to 0.7°) in the writing lineage's entry (MapEntry::normal), so each particle
  /// sees the normals of its own history, as it sees its own stops: one normal per cell shared by all
  /// particles (last writer wins) let a lineage's normals shape the others' scores, and the MIT CSAIL log
  /// closed its big loop cleanly with 14 of filter seeds 1–20 instead of 17 (doc/benchmarks.md). Then
  /// distance through the cell counts along its normal — times |cos| between the beam and the normal,
  /// bounded below by `min_cos` — for every beam that crosses it, in the writes and
  /// in both likelihoods alike, whether the beam ends there or passes by: the cell holds stops per metre of
  /// normal depth. This is setSurfaceDepth for the beams that pass a surface instead of ending on it: the
  /// range noise of a wall's writers leaves stops in the free cells in front of it, and a beam grazing along
  /// the wall through them (towards a corner beyond it) was stopped there early, so that poses moved away
  /// from the wall scored better (the end faces of niches pulled the filter behind, doc/benchmarks.md).
  /// Cells without a normal keep the setSurfaceDepth rule. 0 = off.
  void setCellNormals(double min_cos) { cell_normal_min_cos_ = min_cos; }
  double cellNormals() const { return cell_normal_min_cos_; }
  /// Sub-cell surface positions (with setCellNormals). A cell with a normal also keeps where along it the
  /// surface lies: the mean, over the stops in it, of the return's offset from the cell's centre along the
  /// normal (MapEntry::offset, to 0.6 % of a cell). A stop in that cell is then scored at the point where the
  /// beam crosses that line (clamped to the beam's chord through the cell) instead of at the chord's middle:
  /// a wall's range is known to a fraction of a cell wherever it lies against the grid, as an NDT cell's
  /// mean is. Without it, walls that happen to lie on cell boundaries (parallel to the rows) are all seen at
  /// the same depth, walls between them anywhere within half a cell, and the filter is pulled by the
  /// difference (doc/benchmarks.md, start jitter). false = off.
  void setSurfaceOffsets(bool on) { surface_offsets_ = on; }
  bool surfaceOffsets() const { return surface_offsets_; }
  /// Free-space saturation: a crossed cell whose visible statistics show no hit over at least `distance` m
  /// is not rewritten (its density is 0 either way; this saves a copy per particle of every free cell).
  /// 0 = always write. Set before the first write.
  void setFreeSaturation(double distance);
  /// The ancestry tree's root, whose entries every lineage sees. A cell holding a root entry (or one each
  /// writing lineage sees an entry in, kCovered) and no entry with a hit is free for every particle: the
  /// traces skip its look-up (a byte per cell, beside the tile, instead of the cell's entries: most of a
  /// beam's path is such cells), and whole blocks of such cells at once. -1 = none (no bits, no skips). Set
  /// before the first write; clear() forgets it.
  void setRoot(int node) { root_ = node; }
  /// MapEntry::offset: 0 = none, else k in 1..255 for (k − 128)/127 · 0.75 · resolution m.
  int quantizeOffset(double s) const;
  double offsetValue(int k) const { return (k - 128) * (0.75 * resolution_ / 127.0); }
  /// A quantised normal (MapEntry::normal): 0 = none, else k in 1..255 for the angle (k − ½)·π/255.
  static int quantizeNormal(double nx, double ny);  ///< 0 for (0, 0)
  static int quantizeNormalAngle(double a);         ///< the same for the normal's direction a (rad); 0 for NaN
  /// Node IDs above this do not fit MapEntry::owner (DpSlamConfig caps particles well below it).
  static constexpr int kMaxNodeId = 32767;
  int cellIndex(double v) const { return static_cast<int>(std::floor(v / resolution_)); }

  // --- Raw access ---
  /// The entries of cell (ix, iy) (nullptr and *n = 0 when the cell is unobserved).
  const MapEntry* cellEntries(int ix, int iy, int* n) const;
  std::size_t entryCount() const { return entries_; }          ///< entries in all cells
  std::size_t observedCells() const { return observed_cells_; }  ///< cells with at least one entry
  std::size_t nodeEntryCount(int node) const { return node < static_cast<int>(owned_.size()) ? owned_[node].size() : 0; }
  /// Bytes held by the map (tiles, entry blocks, owner lists), reserved capacity included.
  std::size_t memoryBytes() const;
  /// Cell bounds of the allocated tiles (inclusive); false when the map is empty.
  bool bounds(int* x0, int* y0, int* x1, int* y1) const;

  // --- Reference lookups (no cache) ---
  /// The entry `node` sees in the cell: its own, else its parent's, …; nullptr = unknown.
  const MapEntry* lookup(int ix, int iy, int node, const AncestryTree& tree) const;
  /// lineage_rank[id] = distance of node `id` from the leaf along its lineage (0 = the leaf), or -1 when
  /// not an ancestor: the visible entry is the one of smallest rank. For exporting whole maps.
  const MapEntry* lookup(int ix, int iy, const std::vector<int>& lineage_rank) const;
  static std::vector<int> lineageRank(const AncestryTree& tree, int node);

  // --- Updates (single-threaded) ---
  /// Adds an observation (distance d through the cell, hit or not) to the statistics `node` sees,
  /// updating node's own entry in place or appending a copy of the visible one (unobserved: a fresh
  /// entry with the prior distance). Reference version (walks the tree).
  void observe(int ix, int iy, int node, const AncestryTree& tree, double d, bool hit);
  /// Writes one beam for cache slot `slot` owned by `node` (cache begun with the current leaves): the
  /// cells crossed get (chord, no hit); for a return, the cell holding the endpoint gets (partial chord, hit).
  /// The beam is traced up to `max_range` (m); a return beyond it only writes free space. Crossed cells
  /// that are saturated free (setFreeSaturation) are left as they are.
  void addBeam(const MapBeam& beam, double max_range, int slot, int node, LookupCache& cache);

  /// addBeam in two phases, so that the expensive part can run in parallel: planBeam (const, thread-safe
  /// with one cache per thread) traces the beam and appends the cell writes to `out`, leaving out crossed
  /// cells that are already saturated free for `slot`; applyWrites (single-threaded) then performs them
  /// for `node` in order, with the same rules as addBeam.
  struct CellWrite {
    std::int32_t ix, iy;
    float d;               ///< m of beam through the cell
    std::uint8_t hit = 0;  ///< 1 for the cell where the beam stopped, else 0 (a byte: 16-byte writes)
    std::uint8_t normal = 0;  ///< quantised normal the writer's entry takes (0 = keep its own), see setCellNormals
    std::uint8_t offset = 0;  ///< a stop's quantised offset along the entry's (new) normal (0 = none), see setSurfaceOffsets
  };
  /// `only_unknown`: cells `slot` already has an entry for are left out as well (the map keeps what it has).
  void planBeam(const MapBeam& beam, double max_range, int slot, LookupCache& cache, std::vector<CellWrite>& out,
                bool only_unknown = false) const;
  void applyWrites(const std::vector<CellWrite>& writes, int slot, int node, LookupCache& cache);

  // --- Observation model (const, thread-safe with one cache per thread) ---
  /// log p(beam | map seen by slot), floored at model.log_floor. Traced up to min(range + window, max_range).
  double beamLogLikelihood(const MapBeam& beam, double max_range, int slot, LookupCache& cache,
                           const BeamModelConfig& model) const;
  /// Cheap version for culling: only the part of the beam within ±half_window of the measured range,
  /// starting with probability 1 of getting there. No-return beams give 0.
  double beamEndpointLogLikelihood(const MapBeam& beam, double half_window, int slot, LookupCache& cache,
                                   const BeamModelConfig& model) const;
  /// The visible entry for slot via the cache (nullptr = unknown). Mainly for tests.
  const MapEntry* cachedLookup(int ix, int iy, int slot, LookupCache& cache) const;

  // --- AncestryHooks ---
  void deleteNode(int id) override;
  void mergeChildIntoParent(int child, int parent) override;

  /// Consistency of the back-indices between cells and owner lists, and of the counters; empty if fine.
  std::string check() const;

  static constexpr int kTileShift = 6;  ///< tiles of 64 × 64 cells
  static constexpr int kTileSize = 1 << kTileShift;

 private:
  struct Cell {
    MapEntry* entries = nullptr;  ///< the block's address (re-set when compaction moves it): one load less per look-up
    std::uint32_t block = 0;
    std::uint16_t size = 0;
    std::uint8_t cls = 0xFF;  ///< size class of the block (EntryPool::capacity); 0xFF = none
  };
  /// Tile::free bits (setRoot): every slot sees an entry in the cell (it holds a root entry, or kCovered)
  /// and no entry has a hit: its density is 0 for every slot ...
  static constexpr std::uint8_t kFreeForAll = 1;
  /// ... and every entry has seen at least the free saturation distance (setFreeSaturation): no write
  /// changes what any slot sees.
  static constexpr std::uint8_t kSaturated = 2;
  /// Every particle sees an entry in the cell, its own lineage's or an ancestor's, though the root has none
  /// (a cell each lineage wrote since their last common ancestor). Found when applyWrites builds the cell's
  /// row; it then stays true: a new leaf descends from a covered one, a merge moves an entry to the parent
  /// of the same leaves, and a node loses its entries only when no leaf descends from it any more.
  static constexpr std::uint8_t kCovered = 4;
  /// The bits may be clear where they could be set (a trace then looks the cell up): after a removal they
  /// are recomputed only in cells left with this many entries or fewer.
  static constexpr int kFreeRescanSize = 4;
  static constexpr int kBlockCells = 1 << kTraceBlockShift;
  static constexpr int kBlocksPerTile = (kTileSize / kBlockCells) * (kTileSize / kBlockCells);
  static int blockOf(int cell) {
    return ((cell >> (kTileShift + kTraceBlockShift)) * (kTileSize / kBlockCells)) |
           ((cell & (kTileSize - 1)) >> kTraceBlockShift);
  }

  struct Tile {
    int tx = 0, ty = 0;
    Cell cells[kTileSize * kTileSize];
    std::uint8_t free[kTileSize * kTileSize] = {};  ///< kFreeForAll | kSaturated | kCovered per cell (refreshFree)
    /// The bits every cell of a block of the traces' size (kTraceBlockShift) has: a trace that needs
    /// neither kind of cell skips the block at once (traceCells' kTraceSkipBlock).
    std::uint8_t block_free[kBlocksPerTile] = {};
  };
  /// A trace's step past a cell whose free bits hold `flag`: the rest of its block too when every cell of the
  /// block holds it (traceCells' kTraceSkipBlock), else the next cell.
  static int passFree(const Tile& t, int cell, std::uint8_t flag) {
    return (t.block_free[blockOf(cell)] & flag) ? kTraceSkipBlock : kTraceNext;
  }
  /// A cell's Tile::free bits can only drop to `bits` (an entry appended or changed): its block's with them.
  static void lowerFree(Tile& t, int cell, std::uint8_t bits);
  struct EntryRef {
    std::uint32_t tile;
    std::uint16_t cell;
    std::uint16_t slot;
  };
  class EntryPool;

  int tileId(int ix, int iy) const;  ///< -1 when not allocated
  int ensureTile(int ix, int iy);
  static int cellInTile(int ix, int iy) { return ((iy & (kTileSize - 1)) << kTileShift) | (ix & (kTileSize - 1)); }
  MapEntry* entriesOf(const Cell& c) const;
  void setBlock(Cell& c, int cls, std::uint32_t block);  ///< c takes block `block` of class `cls`
  void moveToClass(Cell& c, int cls);  ///< copies c's entries to a new block of class `cls`
  /// Appends an entry to the cell (growing its block); returns its slot.
  int appendEntry(int tile, int cell, const MapEntry& e);
  /// Removes the entry at `slot` (swap with the last, fixing the moved entry's back-reference) and
  /// shrinks/frees the block. Does not touch the removed entry's owner list.
  void removeFromCell(int tile, int cell, int slot);
  void removeFromOwner(int owner, std::uint32_t back);
  /// Recomputes the cell's Tile::free bits after its entries changed.
  void refreshFree(int tile, int cell);
  /// The Tile::free bits a cell holding only e would have; kSaturated is also the per-entry rule by which
  /// planBeam and applyWrites leave a crossed cell as it is.
  std::uint8_t freeBits(const MapEntry& e) const;
  /// Compacts the entry block classes that have many free blocks (EntryPool::compact). Moves blocks:
  /// only where no entry pointer is held.
  void compactPool();
  /// The tile under a trace, kept while the trace stays in it.
  struct Cursor {
    int tx = std::numeric_limits<int>::min(), ty = 0;
    int tile = -1;
    Tile* t = nullptr;
    void* rows = nullptr;  ///< the cache's TileRows of this tile
  };
  /// Moves the cursor to the tile of (ix, iy) (creating it when `create`); false if it does not exist.
  bool seek(Cursor& cur, int ix, int iy, LookupCache& cache, bool create);
  bool seek(Cursor& cur, int ix, int iy, LookupCache& cache) const;
  /// The entry slot sees in the cursor's cell (nullptr = unknown).
  MapEntry* resolve(const Cursor& cur, int cell, int slot, LookupCache& cache) const;
  const MapEntry* visibleCached(int tile, int cell, int slot, LookupCache& cache) const;
  void buildRow(int tile, int cell, LookupCache& cache) const;
  /// The entry index each slot sees in cell c (-1 = none), into out: from the slots' masks (LookupCache::
  /// descendants_), or by walking each slot's ancestry up to a node with an entry (memoised per cell).
  void rowFromMasks(const Cell& c, const LookupCache& cache, std::int16_t* out) const;
  void rowFromWalks(const Cell& c, LookupCache& cache, std::int16_t* out) const;
  static void setRowSlot(LookupCache& cache, int tile, int cell, int slot, int value);

  double resolution_;
  double prior_distance_;  ///< m
  double surface_depth_ = 0.0;  ///< m, see setSurfaceDepth
  double cell_normal_min_cos_ = 0.0;  ///< see setCellNormals
  bool surface_offsets_ = false;      ///< see setSurfaceOffsets
  float free_saturation_ = std::numeric_limits<float>::infinity();  ///< m, see setFreeSaturation (inf = off)
  int root_ = -1;                     ///< see setRoot
  /// Beam parameter t (m) at which a stop in cell (ix, iy) with normal q and offset k counts: the beam's
  /// crossing of the cell's surface line, clamped to [t0, t1]; the chord's middle without one.
  double stopPoint(int ix, int iy, int q, int k, const MapBeam& b, double t0, double t1) const;
  /// The running mean of an entry's offset after one more stop at `hit_offset` (quantised, along normal
  /// `new_q`), from `old_k` along `old_q` over `old_hits` stops (an old stop without an offset counts as the
  /// cell's centre).
  std::uint8_t meanOffset(int old_q, int old_k, double old_hits, int new_q, int hit_offset) const;
  /// What a chord of beam b through a cell counts for: along the cell's quantised normal q when it has one
  /// (setCellNormals), else along the normal of the surface b ends on when `near_return` (setSurfaceDepth).
  double chordFactor(int q, const MapBeam& b, bool near_return) const;
  std::vector<std::unique_ptr<Tile>> tiles_;
  std::vector<std::int32_t> directory_;  ///< tile IDs over [tx0, tx0 + ntx) × [ty0, ty0 + nty)
  int tx0_ = 0, ty0_ = 0, ntx_ = 0, nty_ = 0;
  std::unique_ptr<EntryPool> pool_;
  std::vector<std::vector<EntryRef>> owned_;  ///< by node ID
  std::size_t entries_ = 0;
  std::size_t observed_cells_ = 0;
};

}  // namespace laser_dpslam
