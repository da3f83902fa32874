#include "mesh/io/TextCursor.h"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "core/Error.h"

namespace plano::io {
namespace {

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Bytes that never occur in a text mesh file: a sign of binary data.
bool isControl(char c) {
  const auto u = static_cast<unsigned char>(c);
  return (u < 0x20 && !isBlank(c) && c != '\n') || u == 0x7f;
}

/// from_chars accepts a leading '-' but not '+': drop one '+' (but not "+-1").
std::string_view withoutPlus(std::string_view token) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+') token.remove_prefix(1);
  return token;
}

}  // namespace

std::string quotedToken(std::string_view token) {
  constexpr std::size_t kMax = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (c < 0x20 || c >= 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (token.size() > kMax) out += "...";
  return out + "'";
}

TextCursor::TextCursor(std::string_view text, std::string source, char commentChar, std::size_t firstLine)
    : text_(text), source_(std::move(source)), comment_(commentChar), line_(firstLine) {}

void TextCursor::skipBlanks() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (isBlank(c)) {
      ++pos_;
    } else if (comment_ != '\0' && c == comment_) {
      while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    } else {
      return;
    }
  }
}

bool TextCursor::tokenOnLine(std::string_view& token) {
  skipBlanks();
  token = {};
  if (pos_ >= text_.size() || text_[pos_] == '\n') return false;
  const std::size_t begin = pos_;
  while (pos_ < text_.size() && !isBlank(text_[pos_]) && text_[pos_] != '\n' &&
         !(comment_ != '\0' && text_[pos_] == comment_)) {
    if (isControl(text_[pos_])) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", static_cast<unsigned char>(text_[pos_]));
      fail(std::string("binary data (byte ") + hex + ") in a text file");
    }
    ++pos_;
  }
  token = text_.substr(begin, pos_ - begin);
  return true;
}

bool TextCursor::token(std::string_view& token) {
  while (true) {
    if (tokenOnLine(token)) return true;
    if (pos_ >= text_.size()) return false;
    ++pos_;  // the '\n'
    ++line_;
  }
}

void TextCursor::skipLine() {
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  if (pos_ < text_.size()) {
    ++pos_;
    ++line_;
  }
}

bool TextCursor::atEnd() {
  while (true) {
    skipBlanks();
    if (pos_ >= text_.size()) return true;
    if (text_[pos_] != '\n') return false;
    ++pos_;
    ++line_;
  }
}

void TextCursor::fail(const std::string& message) const { failAt(line_, message); }

void TextCursor::failAt(std::size_t line, const std::string& message) const {
  throwBadInput(source_ + ":" + std::to_string(line) + ": " + message);
}

double TextCursor::toDouble(std::string_view token, const char* what, bool allowNonFinite) const {
  const std::string_view digits = withoutPlus(token);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (end != digits.data() + digits.size() || digits.empty() ||
      (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    fail(std::string(what) + " " + quotedToken(token) + " is not a number");
  }
  if (ec == std::errc::result_out_of_range) {
    fail(std::string(what) + " " + quotedToken(token) + " is out of the range of double precision");
  }
  if (!allowNonFinite && !std::isfinite(value)) fail(std::string(what) + " " + quotedToken(token) + " is not finite");
  return value;
}

std::int64_t TextCursor::toInteger(std::string_view token, const char* what) const {
  const std::string_view digits = withoutPlus(token);
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (end != digits.data() + digits.size() || digits.empty() ||
      (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    fail(std::string(what) + " " + quotedToken(token) + " is not an integer");
  }
  if (ec == std::errc::result_out_of_range) fail(std::string(what) + " " + quotedToken(token) + " is too large");
  return value;
}

}  // namespace plano::io
