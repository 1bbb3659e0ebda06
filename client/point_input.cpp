#include "client/point_input.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/base/status_macros.hpp"
#include "core/io/las_reader.hpp"
#include "core/io/point_formats.hpp"
#include "core/io/vector_points.hpp"

namespace galpha::alphactl {

namespace {

/// Bytes asked of read(2) at a time.
constexpr size_t kReadChunkBytes = size_t{64} << 10;

/// The first line of every batch after the one that held the input's first record (below).
constexpr absl::string_view kSentinelLine = "0 0\n";
constexpr absl::string_view kWeightedSentinelLine = "0 0 0\n";

// The lines ParsePointsText skips (empty after trimming, or a '#' comment). Only used to know when
// the input's first other line, the one that may be a header, has been parsed.
bool IsSkippedLine(absl::string_view line) {
  line = absl::StripAsciiWhitespace(line);
  return line.empty() || line[0] == '#';
}

absl::Status TooManyPoints(const std::string& source, uint64_t max_points) {
  return absl::ResourceExhaustedError(
      absl::StrCat(source, ": more than ", max_points, " points, the limit (--max-points raises it)"));
}

/// Delimited text fed in pieces of any size and parsed by ParsePointsText in batches of whole
/// lines. ParsePointsText takes the first line it does not skip as a header when it is not numeric;
/// only the input's first such line may be one, so every batch after the one that held it starts
/// with a numeric sentinel line (whose point is dropped), and a non-numeric line there is an error
/// as it would be in one whole parse.
class TextBatches {
 public:
  /// `weighted`: records are x, y and a weight (ParseWeightedPointsText).
  TextBatches(const std::string& source, const InputOptions& options, bool weighted = false)
      : source_(source), options_(options), weighted_(weighted) {}

  /// Appends `bytes`, parsing each batch as it fills.
  absl::Status Append(absl::string_view bytes) {
    while (!bytes.empty()) {
      const size_t newline = bytes.find('\n');
      const bool line_ends = newline != absl::string_view::npos;
      const absl::string_view piece = bytes.substr(0, line_ends ? newline + 1 : bytes.size());
      batch_.append(piece.data(), piece.size());
      bytes_read_ += piece.size();
      bytes.remove_prefix(piece.size());
      const size_t line_bytes = batch_.size() - line_start_ - (line_ends ? 1 : 0);
      if (line_bytes > options_.max_line_bytes) {
        return absl::ResourceExhaustedError(absl::StrCat(source_, ": line ", lines_ + 1, " (from byte offset ",
                                                         line_offset_, ") is longer than ", options_.max_line_bytes,
                                                         " bytes, the limit for one line of delimited text"));
      }
      if (!line_ends) break;
      if (!header_decided_ && !IsSkippedLine(absl::string_view(batch_).substr(line_start_))) batch_has_record_ = true;
      ++lines_;
      line_start_ = batch_.size();
      line_offset_ = bytes_read_;
      if (batch_.size() >= options_.batch_bytes) GALPHA_RETURN_IF_ERROR(ParseBatch());
    }
    return absl::OkStatus();
  }

  /// Parses the last batch (its last line may lack a '\n') and hands over the points (and, weighted,
  /// their weights).
  absl::StatusOr<GeoreferencedPoints> Finish() && {
    if (batch_.size() > (sentinel_ ? Sentinel().size() : 0)) GALPHA_RETURN_IF_ERROR(ParseBatch());
    GeoreferencedPoints out;
    out.points = std::move(points_);
    out.weights = std::move(weights_);
    return out;
  }

 private:
  absl::string_view Sentinel() const { return weighted_ ? kWeightedSentinelLine : kSentinelLine; }

  absl::StatusOr<GeoreferencedPoints> Parse(const std::string& text) const {
    if (weighted_) return ParseWeightedPointsText(text, source_);
    GALPHA_ASSIGN_OR_RETURN(std::vector<Point2> points, ParsePointsText(text, source_));
    GeoreferencedPoints out;
    out.points = std::move(points);
    return out;
  }

  absl::Status ParseBatch() {
    absl::StatusOr<GeoreferencedPoints> parsed = Parse(batch_);
    if (!parsed.ok()) return Renumbered(parsed.status());
    const size_t skip = sentinel_ ? 1 : 0;
    points_.insert(points_.end(), parsed->points.begin() + skip, parsed->points.end());
    if (weighted_) weights_.insert(weights_.end(), parsed->weights.begin() + skip, parsed->weights.end());
    if (points_.size() > options_.max_points) return TooManyPoints(source_, options_.max_points);
    header_decided_ = header_decided_ || batch_has_record_;
    batch_has_record_ = false;
    batch_first_line_ = lines_ + 1;
    sentinel_ = header_decided_;
    batch_.clear();  // keeps its capacity for the next batch
    if (sentinel_) batch_.append(Sentinel().data(), Sentinel().size());
    line_start_ = batch_.size();
    return absl::OkStatus();
  }

  // The parser numbers the lines of the batch; parsing it again behind empty lines (skipped, and
  // the sentinel on the line before the batch) gives the error the input's line numbers. Memory
  // of one byte per earlier line, on this error path only.
  absl::Status Renumbered(const absl::Status& batch_error) const {
    if (batch_first_line_ == 1) return batch_error;
    std::string padded(batch_first_line_ - 1 - (sentinel_ ? 1 : 0), '\n');
    padded += batch_;
    absl::StatusOr<GeoreferencedPoints> again = Parse(padded);
    return again.ok() ? batch_error : again.status();
  }

  const std::string& source_;
  const InputOptions& options_;
  bool weighted_;
  std::vector<Point2> points_;
  std::vector<double> weights_;
  std::string batch_;              // whole lines, then the start of the next; after the sentinel if sentinel_
  bool sentinel_ = false;          // batch_ starts with kSentinelLine
  bool header_decided_ = false;    // an earlier batch held a line the parser does not skip
  bool batch_has_record_ = false;  // this batch holds one
  uint64_t batch_first_line_ = 1;  // the input's number of batch_'s first line (after the sentinel)
  uint64_t lines_ = 0;             // complete lines so far
  size_t line_start_ = 0;          // where the current line starts in batch_
  uint64_t line_offset_ = 0;       // its byte offset in the input
  uint64_t bytes_read_ = 0;
};

/// Closes a descriptor this file opened.
class OwnedFd {
 public:
  explicit OwnedFd(int fd) : fd_(fd) {}
  OwnedFd(const OwnedFd&) = delete;
  OwnedFd& operator=(const OwnedFd&) = delete;
  ~OwnedFd() {
    if (fd_ >= 0) close(fd_);
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

/// "a directory", "a character device", ...: what a refused input is, for its error.
const char* KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file or a pipe";
}

bool IsReadable(mode_t mode) { return S_ISREG(mode) || S_ISFIFO(mode); }

// The readers that stop at the limit themselves say "the limit"; alphactl names its option.
absl::Status WithMaxPointsHint(const absl::Status& status) {
  if (status.code() != absl::StatusCode::kResourceExhausted) return status;
  return absl::ResourceExhaustedError(absl::StrCat(status.message(), " (--max-points raises it)"));
}

template <typename T>
absl::StatusOr<T> WithMaxPointsHint(absl::StatusOr<T> read) {
  if (read.ok()) return read;
  return WithMaxPointsHint(read.status());
}

/// Delimited text from `fd` in batches (TextBatches), weighted or not.
absl::StatusOr<GeoreferencedPoints> ReadTextInput(int fd, const std::string& source, const InputOptions& options,
                                                  bool weighted);

absl::StatusOr<std::vector<Point2>> CheckCount(absl::StatusOr<std::vector<Point2>> points, const std::string& source,
                                               uint64_t max_points) {
  if (points.ok() && points->size() > max_points) return TooManyPoints(source, max_points);
  return points;
}

}  // namespace

absl::StatusOr<std::vector<Point2>> ReadTextPoints(int fd, const std::string& source, const InputOptions& options) {
  GALPHA_ASSIGN_OR_RETURN(GeoreferencedPoints read, ReadTextInput(fd, source, options, /*weighted=*/false));
  return std::move(read.points);
}

namespace {

absl::StatusOr<GeoreferencedPoints> ReadTextInput(int fd, const std::string& source, const InputOptions& options,
                                                  bool weighted) {
  TextBatches batches(source, options, weighted);
  std::string buffer(kReadChunkBytes, '\0');
  while (true) {
    const ssize_t got = read(fd, buffer.data(), buffer.size());
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return absl::ErrnoToStatus(errno, absl::StrCat("cannot read ", source));
    if (got == 0) break;
    GALPHA_RETURN_IF_ERROR(batches.Append(absl::string_view(buffer.data(), static_cast<size_t>(got))));
  }
  return std::move(batches).Finish();
}

/// fstat of standard input, refused unless it is a pipe or a regular file (a terminal, a
/// character device, most likely means the pipe was forgotten).
absl::Status CheckStandardInput(struct stat* info) {
  if (fstat(STDIN_FILENO, info) != 0) return absl::ErrnoToStatus(errno, "cannot inspect standard input");
  if (!IsReadable(info->st_mode)) {
    return absl::InvalidArgumentError(
        absl::StrCat("standard input is ", KindOf(info->st_mode), ": pipe the points in, or name a file"));
  }
  return absl::OkStatus();
}

/// stat of `file` (`named` in messages), refused before it is opened unless it is a regular file
/// or a named pipe: opening a device can block or act (a terminal, a tape).
absl::Status CheckNamedInput(const std::string& file, const std::string& named, struct stat* info) {
  if (stat(file.c_str(), info) != 0) {
    if (errno == ENOENT) return absl::NotFoundError(absl::StrCat(named, " does not exist"));
    return absl::ErrnoToStatus(errno, absl::StrCat("cannot inspect ", named));
  }
  if (!IsReadable(info->st_mode)) {
    return absl::InvalidArgumentError(absl::StrCat(named, " is ", KindOf(info->st_mode),
                                                   ": alphactl reads regular files, named pipes and '-' "
                                                   "(standard input)"));
  }
  return absl::OkStatus();
}

/// The weighted read of ReadInputPointsAndCrs (weights as stored; the caller squares radii).
absl::StatusOr<GeoreferencedPoints> ReadWeightedInput(const std::string& file, const InputOptions& options,
                                                      bool molecule, bool las) {
  const std::string extension = absl::AsciiStrToLower(std::filesystem::path(file).extension().string());
  struct stat info {};
  if (file == "-") {
    GALPHA_RETURN_IF_ERROR(CheckStandardInput(&info));
    return ReadTextInput(STDIN_FILENO, "standard input", options, /*weighted=*/true);
  }
  const std::string named = absl::StrCat("points file '", file, "'");
  if (molecule) {
    // Atoms carry their elements' van der Waals radii (ReadMoleculePoints): radii, not weights.
    if (options.weights != InputOptions::Weights::kRadius) {
      return absl::InvalidArgumentError(absl::StrCat(
          "structure file '", file,
          "': its atoms carry radii (their elements' van der Waals radii): read them with --weights radius"));
    }
    std::vector<double> radii;
    GALPHA_ASSIGN_OR_RETURN(GeoreferencedPoints atoms,
                            WithMaxPointsHint(ReadMoleculePoints(file, options.section, options.max_points, &radii)));
    atoms.weights = std::move(radii);  // radii: the caller adds --probe and squares them
    for (size_t i = 0; i < atoms.weights.size(); ++i) {
      if (std::isnan(atoms.weights[i])) {
        return absl::InvalidArgumentError(
            absl::StrCat("structure file '", file, "': atom ", i,
                         " (in file order, of those kept) has an element gemmi does not know: its van der Waals "
                         "radius is unknown"));
      }
    }
    return atoms;
  }
  if (las || IsVectorPointsExtension(extension)) {
    return absl::InvalidArgumentError(
        absl::StrCat(named,
                     " carries no weights that --weights reads: weighted points come as delimited text (x, y, weight), "
                     ".npy (N, 3), weighted .bin, GeoJSON with --weight-property, or PDB and mmCIF structures "
                     "(their atoms' element radii, with --weights radius)"));
  }
  GALPHA_RETURN_IF_ERROR(CheckNamedInput(file, named, &info));
  const bool text = extension != ".bin" && extension != ".npy" && extension != ".geojson" && extension != ".json";
  if (S_ISFIFO(info.st_mode) && !text) {
    return absl::InvalidArgumentError(absl::StrCat(named, " is a named pipe: only delimited text is read from pipes"));
  }
  if (text) {
    OwnedFd fd(open(file.c_str(), O_RDONLY | O_CLOEXEC));
    if (fd.get() < 0) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open ", named));
    return ReadTextInput(fd.get(), file, options, /*weighted=*/true);
  }
  if (extension == ".bin" && static_cast<uint64_t>(info.st_size) >= 8 &&
      (static_cast<uint64_t>(info.st_size) - 8) / 24 > options.max_points) {
    return absl::ResourceExhaustedError(
        absl::StrCat(named, " has ", info.st_size, " bytes, room for ", (static_cast<uint64_t>(info.st_size) - 8) / 24,
                     " weighted points: more than ", options.max_points, ", the limit (--max-points raises it)"));
  }
  GALPHA_ASSIGN_OR_RETURN(GeoreferencedPoints read, ReadWeightedPointsFile(file, options.weight_property));
  if (read.points.size() > options.max_points) return TooManyPoints(named, options.max_points);
  return read;
}

}  // namespace

absl::StatusOr<std::vector<Point2>> ReadInputPoints(const std::string& file, const InputOptions& options) {
  GALPHA_ASSIGN_OR_RETURN(GeoreferencedPoints read, ReadInputPointsAndCrs(file, options));
  return std::move(read.points);
}

absl::StatusOr<GeoreferencedPoints> ReadInputPointsAndCrs(const std::string& file, const InputOptions& options) {
  const std::string extension = absl::AsciiStrToLower(std::filesystem::path(file).extension().string());
  // A structure may be gzip-compressed: its format is the extension before ".gz".
  const bool molecule =
      IsMoleculeExtension(extension) ||
      (extension == ".gz" &&
       IsMoleculeExtension(absl::AsciiStrToLower(std::filesystem::path(file).stem().extension().string())));
  const bool geojson = extension == ".geojson" || extension == ".json";
  if (!options.group_by.empty() && (file == "-" || !(geojson || IsVectorPointsExtension(extension)))) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--group-by reads the properties of GeoJSON features and the fields of .shp, .gpkg and .fgb layers, not ",
        file == "-" ? "standard input" : absl::StrCat("'", file, "'")));
  }
  if (options.molecule_options && (file == "-" || !molecule)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--plane and --slab apply to PDB and mmCIF structures (.pdb, .ent, .cif, .mmcif), not to ",
                     file == "-" ? "standard input" : absl::StrCat("'", file, "'")));
  }
  if (!options.layer.empty() && (file == "-" || !IsVectorPointsExtension(extension))) {
    return absl::InvalidArgumentError(
        absl::StrCat("--layer applies to Shapefiles, GeoPackages and FlatGeobuf files (.shp, .gpkg, .fgb), not to ",
                     file == "-" ? "standard input" : absl::StrCat("'", file, "'")));
  }
  if (options.weights == InputOptions::Weights::kNone && !options.weight_property.empty()) {
    return absl::InvalidArgumentError("--weight-property names where the weights are: it needs --weights");
  }
  if (options.weights != InputOptions::Weights::kNone) {
    if (!options.weight_property.empty() && (file == "-" || !geojson)) {
      return absl::InvalidArgumentError(absl::StrCat("--weight-property applies to GeoJSON features, not to ",
                                                     file == "-" ? "standard input" : absl::StrCat("'", file, "'")));
    }
    if (geojson && options.weight_property.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "'", file, "' is GeoJSON: name the feature property that holds the weights (--weight-property)"));
    }
    const bool las = extension == ".las" || extension == ".laz";
    GALPHA_ASSIGN_OR_RETURN(GeoreferencedPoints weighted, ReadWeightedInput(file, options, molecule, las));
    if (options.weights == InputOptions::Weights::kRadius) {
      for (size_t i = 0; i < weighted.weights.size(); ++i) {
        const double r = weighted.weights[i];
        if (r < 0.0) {
          return absl::InvalidArgumentError(absl::StrCat(
              "point ", i, " has a negative radius (", r,
              "); radii must be >= 0 (--weights squared reads the values as squared radii, which may be negative)"));
        }
        // The weight is the double nearest (r + probe)^2, r + probe rounded first (--probe); a
        // radius of 2^500 or more has no weight in the domain.
        const double grown = r + options.probe;
        weighted.weights[i] = grown * grown;
        if (std::isfinite(r) && !(weighted.weights[i] < 0x1p1000)) {
          return absl::InvalidArgumentError(
              absl::StrCat("point ", i, " has a radius of ", r, ": radii must be below 2^500 (~3.27e150)"));
        }
      }
    }
    return weighted;
  }
  struct stat info {};
  GeoreferencedPoints read;
  if (file == "-") {
    const std::string source = "standard input";
    GALPHA_RETURN_IF_ERROR(CheckStandardInput(&info));
    GALPHA_ASSIGN_OR_RETURN(read.points, ReadTextPoints(STDIN_FILENO, source, options));
    return read;
  }

  const std::string named = absl::StrCat("points file '", file, "'");
  GALPHA_RETURN_IF_ERROR(CheckNamedInput(file, named, &info));
  const bool las = extension == ".las" || extension == ".laz";
  const bool text = extension != ".bin" && extension != ".npy" && extension != ".geojson" && extension != ".json" &&
                    !las && !IsVectorPointsExtension(extension) && !molecule;
  if (S_ISFIFO(info.st_mode) && !text) {
    // Their readers need the whole input at once, or seek: only a file's size bounds it in advance.
    return absl::InvalidArgumentError(
        absl::StrCat(named,
                     " is a named pipe: only delimited text is read from pipes (.bin, "
                     ".npy, GeoJSON, LAS, GDAL sources and structures need a regular file)"));
  }
  if (extension == ".laz") {
    return absl::InvalidArgumentError(
        absl::StrCat(named,
                     " is compressed LAS (LAZ), which is not read: decompress it to .las first (laszip, pdal "
                     "translate)"));
  }
  if (las) return WithMaxPointsHint(ReadLasPoints(file, options.max_points));
  if (molecule) return WithMaxPointsHint(ReadMoleculePoints(file, options.section, options.max_points));
  if (IsVectorPointsExtension(extension)) {
    return WithMaxPointsHint(ReadVectorPoints(file, options.layer, options.max_points, options.group_by));
  }
  if (geojson && !options.group_by.empty()) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open ", named));
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) return absl::DataLossError(absl::StrCat("cannot read ", named));
    GALPHA_ASSIGN_OR_RETURN(read, ParseGeoreferencedGeoJson(bytes, file, options.group_by));
    if (read.points.size() > options.max_points) {
      return absl::ResourceExhaustedError(absl::StrCat(named, " has ", read.points.size(), " points: more than ",
                                                       options.max_points, ", the limit (--max-points raises it)"));
    }
    return read;
  }
  if (text) {
    OwnedFd fd(open(file.c_str(), O_RDONLY | O_CLOEXEC));
    if (fd.get() < 0) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open ", named));
    // The path may have changed since stat(): what was opened is what counts.
    if (fstat(fd.get(), &info) != 0) return absl::ErrnoToStatus(errno, absl::StrCat("cannot inspect ", named));
    if (!IsReadable(info.st_mode)) return absl::InvalidArgumentError(absl::StrCat(named, " is ", KindOf(info.st_mode)));
    GALPHA_ASSIGN_OR_RETURN(read.points, ReadTextPoints(fd.get(), file, options));
    return read;
  }
  // A .bin holds its points in 16 bytes each after an 8-byte header (and ReadPointsFile checks
  // that its header agrees): its size alone shows that it is over the limit.
  if (extension == ".bin" && static_cast<uint64_t>(info.st_size) >= 8 &&
      (static_cast<uint64_t>(info.st_size) - 8) / sizeof(Point2) > options.max_points) {
    return absl::ResourceExhaustedError(absl::StrCat(
        named, " has ", info.st_size, " bytes, room for ", (static_cast<uint64_t>(info.st_size) - 8) / sizeof(Point2),
        " points: more than ", options.max_points, ", the limit (--max-points raises it)"));
  }
  GALPHA_ASSIGN_OR_RETURN(read, ReadGeoreferencedPointsFile(file));
  GALPHA_ASSIGN_OR_RETURN(read.points, CheckCount(std::move(read.points), named, options.max_points));
  return read;
}

}  // namespace galpha::alphactl
