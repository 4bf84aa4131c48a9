#pragma once
/// docs/RESULTS.md is assembled from sections, each owned by one command (the detector
/// benchmark, the SLAM benchmark, the navigation benchmark...). A command regenerates only
/// its own section, between `<!-- BEGIN name -->` and `<!-- END name -->` markers, so the
/// file is never edited by hand and commands do not overwrite each other.
///
/// Usage:
///   devslam::core::replaceResultsSection("docs/RESULTS.md", "detect", markdown);

#include <ctime>
#include <filesystem>
#include <string>

namespace devslam::core {

/// Replaces (or appends) the named section; creates the file with a title if missing.
/// Throws std::runtime_error, writing nothing, if the file has only one of the section's
/// markers or its END before its BEGIN, if its name does not end in ".md" (an INI or source
/// file named by mistake), or if the file cannot be written; std::invalid_argument if
/// `name` is empty or contains characters other than [a-z0-9_-].
/// The file is replaced whole (writeFileWhole): a command killed while writing leaves it as
/// it was. Commands writing at once take turns (an exclusive flock on the file's folder held
/// from the read to the rename), so no section is lost.
void replaceResultsSection(const std::string& path, const std::string& name,
                           const std::string& markdown);

/// Writes `text` to `path` whole or not at all: into `path`.part, then renamed over `path`,
/// so that a program killed on the way leaves the old file (and at most the .part beside it,
/// which the next write takes over). Writers of one file at once take turns (each holds the
/// .part, flocked, from its first byte to its rename): the last one's text is the file's,
/// never a splice of two. The file keeps its permissions; a symbolic link stays one (the file
/// it leads to is replaced, or made). Throws std::runtime_error naming the file when it
/// cannot be written, or when its .part is a link or not a plain file.
void writeFileWhole(const std::string& path, const std::string& text);

/// An output folder held by this process for as long as the object lives (an exclusive
/// flock on the folder, taken without waiting), so that a second run writing the same folder
/// at once is refused instead of mixing its files with this one's. The folder is made with
/// its parents if it is not there, and removed again at the end if this made it and it is
/// still empty (a run stopped before its first output). Advisory: devslam-run --out,
/// devslam-synth -o and devslam-overlay --out take it.
class FolderClaim {
  public:
    /// Throws std::runtime_error "'DIR' is being written by another run at the moment; wait
    /// for it or name another folder", or "cannot make folder 'DIR': <why>".
    explicit FolderClaim(const std::string& dir);
    ~FolderClaim();
    FolderClaim(const FolderClaim&) = delete;
    FolderClaim& operator=(const FolderClaim&) = delete;

  private:
    std::string dir_;
    int fd_ = -1;
    bool made_ = false;
};

/// Flushes std::cout and C's stdout and returns `rc`, or 1 where `rc` is 0 and the standard
/// output could not be written (a full disk behind '>': the figures were lost, and the
/// program said 0), saying so on std::cerr as "<program>: cannot write the standard output".
[[nodiscard]] int withStandardOutput(const char* program, int rc);

/// devslam-run's exit status for a whole run in which no frame took a pose (every frame lost;
/// a localizing run that never found itself in the map): its outputs are written, as a run's
/// that tracked, but there is no trajectory to score. 1 stays for errors and stopped runs.
inline constexpr int kExitNoPose = 2;

/// FNV-1a (64 bit) of a file's bytes as 16 hex digits, "" when it cannot be read: tells
/// whether a file's content changed (not a cryptographic hash).
[[nodiscard]] std::string fileHash(const std::string& path);

/// Whether the output `out` exists and is the file or folder `in` (another spelling, a link):
/// writing it would destroy `in`. False when `in` cannot be compared (it does not exist).
[[nodiscard]] bool sameFile(const std::string& in, const std::string& out);

/// Whether a file can be made in the folder `dir`: probed by making one there and removing it
/// (access() says yes to root, and on a read-only mount).
[[nodiscard]] bool canMakeFilesIn(const std::filesystem::path& dir);

/// Where making the folder `folder` (with its parents) starts: `folder` itself, absolute, when
/// it exists, else the nearest of its parents that does (a file, perhaps); for checking an
/// output folder before a long job without making it.
[[nodiscard]] std::filesystem::path nearestExisting(const std::string& folder);

/// What replaceResultsSection would throw for `path` and `name`, found before a command's
/// work (a bad name, broken markers, a folder, a missing parent folder); writes nothing.
void checkResultsSection(const std::string& path, const std::string& name);

/// A file as results name it: relative to `root` (the repository) when it lies in it, else
/// as given.
[[nodiscard]] std::string shownPath(const std::string& path, const std::string& root);

/// The current UTC date-time and host facts ("2026-11-21 06:00 UTC, 2 hardware threads,
/// AMD EPYC (family 25 model 1), OpenCV SIMD AVX2") for a "measured on" line under each
/// table. The SIMD level matters: OpenCV picks its kernels by it at run time, and the same
/// code gives other trajectories with other kernels (docs/bench.md, "Limits").
[[nodiscard]] std::string measuredOnLine();
/// measuredOnLine() without its date: "2 hardware threads, AMD EPYC (family 25 model 1),
/// OpenCV SIMD AVX2" (what decides a run's figures besides its inputs).
[[nodiscard]] std::string hostLine();

/// `t` as "2026-11-27 10:32 UTC", the form measuredOnLine() gives its date in.
[[nodiscard]] std::string utcMinute(std::time_t t);

}  // namespace devslam::core
