#pragma once
/// Strict reading of the MRPT sections of a navigation INI. MRPT's reactive navigator reads
/// its own sections ([CAbstractNavigator], [CAbstractPTGBasedReactive], the PTGs in
/// [CReactiveNavigationSystem], the holonomic methods' sections, ...) with read_double and
/// friends, which take "fast" as 0 and "0.3m/s" as 0.3, and ignore a mistyped key: a run then
/// goes on with other values than the file's, or fails later with a stack trace.
///
/// Usage (readNavigatorOptions does it):
///   devslam::nav::checkMrptSections(cfg, "nav.ini");   // throws std::invalid_argument
#include <mrpt/config/CConfigFileBase.h>

#include <string>

namespace devslam::nav {

/// Checks every key of MRPT's sections in `cfg` against the keys MRPT's own parameter
/// structures write (saveToConfigFile): an unknown key, or a value that does not parse in
/// full where MRPT's default is a number, a list of numbers or a boolean, throws
/// std::invalid_argument "<source> [section] key: ...". The PTGs are made as MRPT makes them
/// (PTG_COUNT, PTG<i>_Type) to learn their keys; a PTG MRPT refuses is named with its index.
void checkMrptSections(const mrpt::config::CConfigFileBase& cfg, const std::string& source);

}  // namespace devslam::nav
