#pragma once
/// Whole-text number parsing for command-line options and INI values. The C and MRPT
/// readers stop at the first character they cannot use: atoi("7x") is 7, atoi("1e3") is 1,
/// std::stoul("-5") wraps to a huge count, and MRPT's read_bool takes "ture" as false.
/// These parse the whole text or throw std::invalid_argument naming `what` and the text.
///
/// Usage:
///   frames = devslam::core::parseInteger(argv[i], "--frames", 1);        // "7x" throws
///   ratio = devslam::core::parseNumber(value, "[tracker] match_ratio");
///   on = devslam::core::parseBool(value, "[local_ba] enabled");

#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace devslam::core {

/// A finite number written in full ("0.5", "-3", "1e-3", and MRPT's $eval{} output
/// "3.000000e+01"); surrounding blanks are ignored. Throws std::invalid_argument
/// "<what>: expected a number, got '<text>'".
[[nodiscard]] double parseNumber(const std::string& text, const std::string& what);

/// Whether `text` (no surrounding blanks) reads in full as one finite number, into `v`: no
/// trailing characters, no nan, inf or overflow ("1e400"), no C hexadecimal ("0x1p-3", which
/// Python's float() refuses). An underflow ("1e-400") reads as the subnormal or 0 it rounds
/// to, as in Python.
[[nodiscard]] bool readFinite(const std::string& text, double& v);

/// An integer in [min, max]. Written in full as parseNumber accepts it, with an integral
/// value ("1e3" is 1000, "2.5" is an error). Throws std::invalid_argument naming `what`,
/// the text and, when it is outside them, the bounds.
[[nodiscard]] long long parseInteger(const std::string& text, const std::string& what,
                                     long long min = std::numeric_limits<long long>::min(),
                                     long long max = std::numeric_limits<long long>::max());

/// true/yes/on/1 or false/no/off/0, in any letter case. Throws std::invalid_argument
/// "<what>: expected true or false, got '<text>'".
[[nodiscard]] bool parseBool(const std::string& text, const std::string& what);

/// Finite numbers written "[a b c]", "a b c" or "a, b, c" (MRPT writes vectors in
/// brackets). Throws std::invalid_argument "<what>: 'x' is not a number" on a bad token,
/// "<what>: 'inf' is not a finite number" on nan, inf or an overflowing one, and "<what>: expected
/// N numbers, got M" when `expected` (if > 0) does not match the count.
[[nodiscard]] std::vector<double> parseNumberList(const std::string& text, const std::string& what,
                                                  std::size_t expected = 0);

/// `text` without the blanks (std::isspace) at its ends.
[[nodiscard]] std::string trimmed(const std::string& text);

/// `text` as it is, or when longer than `max` bytes its first ones, cut at a whole UTF-8
/// character, with "... (N bytes)": for quoting a line or a value in a message (a 500 kB junk
/// line of a world file was quoted whole).
[[nodiscard]] std::string clipped(const std::string& text, std::size_t max = 80);

/// The shortest text that reads back as `v` ("0.2", not "0.200000"), for writing a number.
[[nodiscard]] std::string shortestReal(double v);

/// `text` in lower case (ASCII letters), for names read in any letter case.
[[nodiscard]] std::string lowercase(std::string text);

/// Whether `text` ends in `suffix`, letters compared in any case: a file name's extension
/// (OpenCV picks an image's format by it, ".PNG" as ".png").
[[nodiscard]] bool endsWithNoCase(const std::string& text, const std::string& suffix);
/// Whether `text` ends in `suffix`, case counting (".rawlog", never ".RAWLOG").
[[nodiscard]] bool endsWith(const std::string& text, const std::string& suffix);

/// The value of the command-line option args[i], which is args[i + 1]; `i` moves onto it.
/// Throws std::invalid_argument "<option> needs a value" when there is none or the next word
/// is another option ("--method --png x.png": the value is missing, not "--png"); words with
/// one dash ("-1,2") are values.
[[nodiscard]] std::string optionValue(const std::vector<std::string>& args, std::size_t& i);
/// The same for main's argc/argv.
[[nodiscard]] std::string optionValue(int argc, char** argv, int& i);

/// Throws std::invalid_argument "<option> is given twice ..." when an option of `args`
/// (a word with two dashes: optionValue takes no such word as a value) appears more than
/// once, except those in `repeatable` and --help; a parser kept the last value without a
/// word. `aliases` maps a short spelling to its option ("-o" -> "--out").
void refuseRepeatedOptions(const std::vector<std::string>& args,
                           const std::vector<std::string>& repeatable = {},
                           const std::vector<std::pair<std::string, std::string>>& aliases = {});
/// The same for main's argc/argv (argv[0] is the program).
void refuseRepeatedOptions(int argc, char** argv, const std::vector<std::string>& repeatable = {},
                           const std::vector<std::pair<std::string, std::string>>& aliases = {});

}  // namespace devslam::core
