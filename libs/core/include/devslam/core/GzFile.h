#pragma once
/// Two helpers for files MRPT writes through gzip streams (rawlogs, `.gridmap` archives):
/// MRPT's gz reader stops quietly at a file's cut end, and its exceptions nest their texts
/// several levels deep under banners and stack traces.
///
/// Usage:
///   if (auto d = devslam::core::gzipDamage(path); !d.empty()) throw ...(path + ": " + d);
///   catch (const std::exception& e) { ... devslam::core::innermostMessage(e.what()) ... }
#include <string>

namespace devslam::core {

/// A gzip stream cut short decodes cleanly up to the cut, and MRPT's stream reports a plain
/// end of file there (or, reading an archive, nothing at all); only zlib knows the trailer
/// is missing. Returns "" when the file at `path` is a complete gzip stream or no gzip at
/// all (a plain rawlog); otherwise what zlib says is wrong ("unexpected end of file",
/// "cannot open", ...).
[[nodiscard]] std::string gzipDamage(const std::string& path);

/// The innermost non-empty "Message:" line of an MRPT exception text (its first line when
/// it has none).
[[nodiscard]] std::string innermostMessage(const std::string& what);

}  // namespace devslam::core
