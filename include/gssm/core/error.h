#pragma once
// One exception hierarchy for the whole library. Every message says what was
// wrong, where (variable, file, line, field) and, where we know it, what to do.
#include <stdexcept>
#include <string>

namespace gssm {

/// `text` with every character a reader cannot see written as its code
/// point (<U+200B>; a byte that is not UTF-8 as <0xC3>). Tabs and line
/// breaks stay as they are.
std::string showInvisible(const std::string& text);

/// Base of every exception gssm throws.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// A caller passed something the library cannot use: wrong dimension, NaN,
/// time going backwards, an invalid option.
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

/// A file or configuration could not be read: the message names the file,
/// line, column/field and offending value. Characters a reader cannot see
/// (controls, zero-width and non-breaking spaces, a byte-order mark, bytes
/// that are not UTF-8) are shown as their code point, e.g. <U+FEFF>.
class InputError : public Error {
 public:
  explicit InputError(const std::string& what) : Error(showInvisible(what)) {}
};

/// The numbers went wrong: a covariance that is not positive definite, a
/// rank-deficient information matrix. Names the variables involved.
class NumericalError : public Error {
 public:
  using Error::Error;
};

/// A checkpoint could not be written or read (names the file and, for a
/// corrupted one, the byte offset and the field).
class CheckpointError : public Error {
 public:
  using Error::Error;
};

}  // namespace gssm
