#pragma once
// The frame series of one output folder: a .pvd collection per series
// ("<name>.pvd"), all listing the same frames ("<name>_N.vtu", a distributed
// run's pieces and .pvtu files; io/output_directory.hpp names them), started
// anew in place of an earlier run's or restored as a checkpoint recorded them,
// and the writing of a frame by one process or many.
//
// The collections are always rewritten together (io::write_together), after
// every file of the frame is complete, so at any moment they list the same
// frames and every listed file is whole. A file in the folder that is named
// like a frame but that no run can have written (a folder, a number past any
// frame's) is kept and named on the notes stream.

#include <sphshell/core/error.hpp>
#include <sphshell/io/output_directory.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/vtu_writer.hpp>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace sphshell::io {

class FrameSeries {
 public:
  // One entry of a collection (its file relative to the collection), as a checkpoint stores it.
  struct Entry {
    double time = 0.0;
    std::int32_t part = 0;
    std::string file;
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.time, self.part, self.file);
    }
  };

  // The series `names` in `directory`, empty; notes go to `notes` (std::clog when null).
  FrameSeries(std::string directory, const std::vector<std::string>& names, std::ostream* notes)
      : directory_(std::move(directory)), notes_(notes) {
    make_directory(directory_, "", "output_directory");
    for (const std::string& name : names)
      collections_.push_back(std::make_unique<PvdCollection>(path(name + ".pvd"), false));
  }

  // In place of an earlier run's series: first the collections of series this
  // run does not write (`dropped`), then the collections are replaced
  // together (so that at no moment do they list different frames, or frames
  // that are gone), then the earlier frames and the temporaries of a killed
  // run are removed. Other files stay.
  void start(const std::vector<std::string>& dropped) {
    for (const std::string& name : dropped) remove_file(path(name + ".pvd"));
    write();
    remove_frames(0, true);
  }

  // The collections as a checkpoint had them (`entries`, one list per
  // series), rewritten together; the frames written after the checkpoint
  // (numbers from `frames_written` on) are removed, so the folder is as it was then.
  void restore(const std::vector<std::vector<Entry>>& entries, long frames_written) {
    for (std::size_t k = 0; k < collections_.size() && k < entries.size(); ++k)
      for (const Entry& entry : entries[k]) collections_[k]->stage(entry.time, path(entry.file), entry.part);
    write();
    remove_frames(frames_written, false);
  }

  // A frame file of series k (its path as path() gives it) listed at `time`;
  // write() then rewrites the collections together.
  void stage(std::size_t series, double time, const std::string& file, int part = 0) {
    collections_[series]->stage(time, file, part);
  }
  void write() const {
    std::vector<const PvdCollection*> collections;
    for (const auto& collection : collections_) collections.push_back(collection.get());
    write_together(collections);
  }

  std::size_t size() const { return collections_.size(); }
  std::vector<Entry> entries(std::size_t series) const {
    std::vector<Entry> entries;
    for (const PvdCollection::Entry& entry : collections_[series]->entries())
      entries.push_back({entry.time, static_cast<std::int32_t>(entry.part), entry.file});
    return entries;
  }
  std::string path(const std::string& name) const { return directory_ + "/" + name; }

 private:
  // Frame numbers are longs: digits past one are no frame's.
  static constexpr long unreadable_number = -2;

  // The number N of a frame file "<series>_N.vtu" (a piece, a .pvtu, or
  // their .tmp), -1 for a collection or its .tmp, unreadable_number for
  // digits no long holds.
  static long frame_number(const std::string& name) {
    const std::optional<std::string> digits = frame_file_digits(name);
    if (!digits || digits->empty()) return -1;
    long number = 0;
    const auto [end, error] = std::from_chars(digits->data(), digits->data() + digits->size(), number);
    if (error != std::errc() || end != digits->data() + digits->size()) return unreadable_number;
    return number;
  }

  // Removes the frame files numbered from `first` on; a fresh series
  // (`fresh`) removes every frame file but the collections, their killed
  // temporaries included. What cannot be a frame of a run is kept and named.
  void remove_frames(long first, bool fresh) const {
    namespace fs = std::filesystem;
    std::error_code error;
    std::vector<fs::path> removed;
    for (fs::directory_iterator entry(directory_, error), end; !error && entry != end; entry.increment(error)) {
      const std::string name = entry->path().filename().string();
      if (!is_frame_file(name) || (fresh && name.compare(name.size() - 4, 4, ".pvd") == 0)) continue;
      std::error_code kind_error;
      if (!entry->is_regular_file(kind_error)) {
        note_kept(name, "not a file (a folder, say)");
        continue;
      }
      const long number = frame_number(name);
      if (number == unreadable_number)
        note_kept(name, "numbered past any frame");
      else if (fresh || number >= first)
        removed.push_back(entry->path());
    }
    if (error) throw Error("sphshell: cannot list output_directory '" + directory_ + "' (" + error.message() + ")");
    for (const fs::path& file : removed) remove_file(file.string());
  }

  void note_kept(const std::string& name, const std::string& why) const {
    std::ostream& out = notes_ ? *notes_ : std::clog;
    out << "sphshell: output_directory '" << directory_ << "': kept '" << name
        << "', which is named like a frame file but is " << why
        << "; move it out of the folder to keep it out of the series' way\n";
    out.flush();
  }

  std::string directory_;
  std::ostream* notes_;
  std::vector<std::unique_ptr<PvdCollection>> collections_;
};


// One dataset of a frame: its series and the grid this process drew, in
// pieces (every process its own: serially "<series>_N.vtu", distributed the
// piece "<series>_N_rR.vtu" and, by the first process, a .pvtu naming the
// pieces) or whole (written by the first process as "<series>_N.vtu").
// A dataset may instead be listed in another series' collection
// (`listed_in`) as part `part` of the frame's time, so that one collection
// opens both (a ParaView multiblock); its files keep their own series name.
struct FrameDataset {
  enum class Drawn { in_pieces, whole };
  std::string series;
  VtuGrid grid;
  Drawn drawn = Drawn::in_pieces;
  std::string listed_in = {};  // empty: its own collection, "<series>.pvd"
  int part = 0;
};

// The frames of a run in one output folder, written by the processes of a
// group (domain/domain.hpp: is_distributed, rank, size, is_root,
// collectively, piece_file_of), serially by the one.
class FrameSeriesWriter {
 public:
  FrameSeriesWriter(std::string directory, const VtuFormat& format, std::ostream* notes)
      : directory_(std::move(directory)), format_(format), notes_(notes) {}

  // One frame (collective): its datasets, each a series, listed at `time`.
  // The first frame of a run starts the series anew (FrameSeries::start;
  // `known`: every series a run can write, whose collection goes when this
  // run does not write it).
  template <class Group>
  void write(const Group& group, double time, const std::vector<FrameDataset>& datasets,
             const std::vector<std::string>& known) {
    char digits[32];
    std::snprintf(digits, sizeof digits, "%06ld", written_);
    const std::string number(digits);
    group.collectively([&] {
      if (group.is_root() && !series_) start(datasets, known);
    });
    group.collectively([&] {
      for (const FrameDataset& dataset : datasets)
        if (dataset.drawn == FrameDataset::Drawn::in_pieces)
          write_vtu(path(group.piece_file_of(dataset.series + "_" + number, group.rank())), dataset.grid, format_);
    });
    group.collectively([&] {
      if (!group.is_root()) return;
      const std::vector<std::string> names = collection_names(datasets);
      for (std::size_t k = 0; k < datasets.size(); ++k) {
        const FrameDataset& dataset = datasets[k];
        const std::string frame = dataset.series + "_" + number;
        std::string listed;
        if (dataset.drawn == FrameDataset::Drawn::whole) {
          listed = path(frame + ".vtu");
          write_vtu(listed, dataset.grid, format_);
        } else if (!group.is_distributed) {
          listed = path(group.piece_file_of(frame, 0));
        } else {
          listed = path(frame + ".pvtu");
          std::vector<std::string> pieces;
          for (int r = 0; r < group.size(); ++r) pieces.push_back(group.piece_file_of(frame, r));
          write_pvtu(listed, dataset.grid, pieces, format_.precision);
        }
        series_->stage(collection_of(names, dataset), time, listed, dataset.part);
      }
      series_->write();
    });
    ++written_;
  }

  // The frames written so far in this run.
  long written() const { return written_; }
  // Whether this process keeps the collections (the first, once a frame was written).
  bool has_series() const { return series_.has_value(); }
  // The entries of series k (none past the series this run writes).
  std::vector<FrameSeries::Entry> entries(std::size_t k) const {
    return k < series_->size() ? series_->entries(k) : std::vector<FrameSeries::Entry>{};
  }
  // After a checkpoint: `written` frames, the collections of the series
  // `names` (with `entries`, one list each) when `entries` is not empty,
  // the frames from number `written` on removed.
  void restore(long written, const std::vector<std::string>& names,
               const std::vector<std::vector<FrameSeries::Entry>>& entries) {
    written_ = written;
    series_.reset();
    if (entries.empty()) return;
    series_.emplace(directory_, names, notes_);
    series_->restore(entries, written_);
  }

 private:
  std::string path(const std::string& name) const { return directory_ + "/" + name; }
  // The collections are those of the datasets listed in their own, in order.
  static std::vector<std::string> collection_names(const std::vector<FrameDataset>& datasets) {
    std::vector<std::string> names;
    for (const FrameDataset& dataset : datasets)
      if (dataset.listed_in.empty()) names.push_back(dataset.series);
    return names;
  }
  // The collection a dataset is listed in, among the frame's `names`.
  static std::size_t collection_of(const std::vector<std::string>& names, const FrameDataset& dataset) {
    const std::string& listed = dataset.listed_in.empty() ? dataset.series : dataset.listed_in;
    const auto found = std::find(names.begin(), names.end(), listed);
    if (found == names.end())
      throw Error("sphshell: frame dataset '" + dataset.series + "' is listed in series '" + listed +
                  "', which this frame does not write");
    return static_cast<std::size_t>(found - names.begin());
  }
  void start(const std::vector<FrameDataset>& datasets, const std::vector<std::string>& known) {
    std::vector<std::string> names = collection_names(datasets), dropped;
    for (const std::string& name : known)
      if (std::find(names.begin(), names.end(), name) == names.end()) dropped.push_back(name);
    series_.emplace(directory_, names, notes_);
    series_->start(dropped);
  }

  std::string directory_;
  VtuFormat format_;
  std::ostream* notes_;
  std::optional<FrameSeries> series_;  // the first process's
  long written_ = 0;
};

}  // namespace sphshell::io
