#pragma once
// A strict tokenizer over an in-memory text file, shared by the OBJ, OFF and PLY (ASCII)
// readers: whitespace-separated tokens (CR counts as whitespace, so CRLF files read like
// LF files), '#' comments to the end of a line, a line number for every message, and
// number parsing that rejects anything that is not entirely a number.
//
// Every failure throws Error(BadInput) "SOURCE:LINE: message". Tokens quoted in messages
// are shortened, so a multi-megabyte line never ends up in an error message.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace plano::io {

class TextCursor {
 public:
  /// `text` must outlive the cursor. `commentChar` starts a comment ('\0': none).
  /// `firstLine` is the line number of the text's first line in its file.
  TextCursor(std::string_view text, std::string source, char commentChar = '#', std::size_t firstLine = 1);

  /// The next token on the current line; false (and `token` empty) at the end of the line.
  bool tokenOnLine(std::string_view& token);
  /// The next token, moving across line ends; false at the end of the text.
  bool token(std::string_view& token);
  /// Skip the rest of the current line, including its line end.
  void skipLine();
  /// True when only whitespace and comments remain.
  bool atEnd();
  /// The current line number (1-based).
  std::size_t line() const { return line_; }
  /// Bytes not yet consumed (an upper bound for how many more items the text can hold).
  std::size_t remaining() const { return text_.size() - pos_; }
  /// Position in the text (bytes from its start).
  std::size_t position() const { return pos_; }
  const std::string& source() const { return source_; }

  /// Throw Error(BadInput) "SOURCE:LINE: message".
  [[noreturn]] void fail(const std::string& message) const;
  [[noreturn]] void failAt(std::size_t line, const std::string& message) const;

  /// Parse a whole token as a double (what: used in messages, e.g. "coordinate"); NaN
  /// and Inf are refused unless `allowNonFinite`.
  double toDouble(std::string_view token, const char* what, bool allowNonFinite = false) const;
  /// Parse a whole token as an integer (optionally signed).
  std::int64_t toInteger(std::string_view token, const char* what) const;

 private:
  /// Skip spaces, tabs, CR and comments; stops at '\n' or the end.
  void skipBlanks();

  std::string_view text_;
  std::string source_;
  char comment_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
};

/// A token for an error message: quoted, at most ~40 characters, control bytes escaped.
std::string quotedToken(std::string_view token);

}  // namespace plano::io
