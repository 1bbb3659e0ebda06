// What alphactl reads its points from, and how much of it: every input is bounded, so that a
// device or a pipe that never ends (/dev/zero, `yes`) ends in an error rather than in all of memory.
//
//   regular files   read in their format (point_formats.hpp, las_reader.hpp, vector_points.hpp); a
//                   .bin or a LAS file with more points than the limit allows is refused from its
//                   size or header, before its points are read; GDAL vector sources stop at the limit
//   named pipes     (mkfifo, /dev/stdin, <(cmd)) and '-' (standard input, a pipe or a redirected
//                   file): delimited text only, which is parsed as it streams
//   anything else   (character and block devices, directories, sockets) is refused, naming it
//
// Delimited text, from any of these, is parsed in batches of whole lines, so memory holds the
// points and one batch however the input is laid out; a line longer than max_line_bytes ends the
// read (the one-line records of the format are short: it is how endless bytes without a newline are
// caught). Every input holds at most max_points points.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/base/point.hpp"
#include "core/io/georeferenced_points.hpp"
#include "core/io/molecule_points.hpp"

namespace galpha::alphactl {

/// The server's default --max_points_per_build (server/main.cpp): by default alphactl reads no
/// more than a default server would build.
inline constexpr uint64_t kDefaultMaxPoints = 100'000'000;

/// The default longest line of delimited text (InputOptions::max_line_bytes).
inline constexpr size_t kDefaultMaxLineBytes = size_t{64} << 10;

/// How an input is read and bounded.
struct InputOptions {
  /// More points than this is ResourceExhausted (the command line's --max-points).
  uint64_t max_points = kDefaultMaxPoints;
  /// The longest line of delimited text in bytes, its '\n' apart: a line holds one point and its
  /// attributes, so anything longer is not point data.
  size_t max_line_bytes = kDefaultMaxLineBytes;
  /// Text is parsed in batches of whole lines of about this many bytes (memory, not a limit).
  size_t batch_bytes = size_t{1} << 20;
  /// The layer of a GDAL vector source to read (--layer); empty: its first. Given with any other
  /// input, it is an error.
  std::string layer;
  /// The plane and slab of a PDB or mmCIF structure's atoms (--plane, --slab); `molecule_options`
  /// records that one was given (with any other input, it is an error).
  MoleculeSection section;
  bool molecule_options = false;
  /// A column whose values group the points (--group-by): a GeoJSON feature property or a field of
  /// a GDAL layer; the result's `groups` then holds each point's value. Empty: none.
  std::string group_by;
  /// Weighted points (--weights): none, each point's third value a radius (squared here: the
  /// weight is its square; a negative radius is an error) or a squared radius as it is.
  enum class Weights { kNone, kRadius, kSquared };
  Weights weights = Weights::kNone;
  /// The GeoJSON feature property that holds the weights (--weight-property; GeoJSON only).
  std::string weight_property;
  /// With kRadius: added to every radius before squaring (--probe: a solvent probe's radius, 1.4
  /// angstrom for water, turns van der Waals disks into solvent-accessible ones). >= 0.
  double probe = 0.0;
};

/// Reads the points of `file`, or of standard input when `file` is "-", as the header comment
/// describes. O(input).
///
/// Errors name the file (or "standard input"): NotFound when it does not exist; InvalidArgument when
/// it is a directory, device or socket, or a pipe whose name asks for a format other than delimited
/// text; ResourceExhausted for more than max_points points or a line longer than max_line_bytes (with
/// the line's number and byte offset); errno-derived codes when it cannot be opened or read; the
/// parsers' errors (point_formats.hpp).
absl::StatusOr<std::vector<Point2>> ReadInputPoints(const std::string& file, const InputOptions& options);

/// ReadInputPoints, with the CRS of the files that state one (LAS, GDAL vector sources, GeoJSON);
/// nullopt for the others. Errors as ReadInputPoints's, and InvalidArgument for options.layer with
/// an input that is not a GDAL vector source, for --plane/--slab with one that is no structure, or
/// for a compressed LAS (.laz) file.
///
/// With options.weights, the points come with a weight each (GeoreferencedPoints::weights, as
/// squared radii): from delimited text (x, y, weight; pipes and standard input too), .npy (N, 3),
/// weighted .bin and GeoJSON with options.weight_property (point_formats.hpp); other formats are
/// InvalidArgument, as is weight_property without weights or with another format.
absl::StatusOr<GeoreferencedPoints> ReadInputPointsAndCrs(const std::string& file, const InputOptions& options);

/// Parses the delimited text (ParsePointsText's format) read from descriptor `fd` until its end, in
/// batches of whole lines; `source` names it in errors, whose line numbers count from the start of
/// the stream. Memory: the points and one batch. Errors as ReadInputPoints's.
absl::StatusOr<std::vector<Point2>> ReadTextPoints(int fd, const std::string& source, const InputOptions& options);

}  // namespace galpha::alphactl
