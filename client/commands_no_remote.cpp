// Builds without the service (GALPHA_BUILD_SERVER=OFF) have no --server mode: each remote entry
// point says so as a usage error.
#include "client/commands.hpp"

namespace galpha::alphactl {

namespace {
int NoServer() {
  return UsageError(absl::InvalidArgumentError(
      "this alphactl was built without the service (GALPHA_BUILD_SERVER=OFF): --server is not available"));
}
}  // namespace

int RemoteSpectrum(const CommonArgs&) { return NoServer(); }
int RemoteClassify(const CommonArgs&, const ClassifyArgs&) { return NoServer(); }
int RemoteSummary(const CommonArgs&, const ClassifyArgs&) { return NoServer(); }
int RemoteShape(const CommonArgs&, const ThresholdArg&, ClassifyMode, const std::string&, double) { return NoServer(); }
int RemoteMasterList(const CommonArgs&, int64_t) { return NoServer(); }
int RemoteOptimal(const CommonArgs&, int64_t, std::optional<int64_t>) { return NoServer(); }
int RemoteBench(const CommonArgs&, int64_t) { return NoServer(); }
int RemotePersistence(const CommonArgs&, const PersistenceArgs&) { return NoServer(); }
int RemoteHoles(const CommonArgs&, const HolesArgs&) { return NoServer(); }

}  // namespace galpha::alphactl
