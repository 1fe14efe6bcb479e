#pragma once
// One check for every test of an error message: `fn` must throw E (a gssm
// Error by default) whose message contains each fragment.
#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "gssm/core/error.h"

namespace gssm::testing {

template <class E = Error, class Fn>
void expectThrowsNaming(Fn fn, std::initializer_list<std::string> fragments) {
  try {
    fn();
    ADD_FAILURE() << "no exception; expected one naming '" << *fragments.begin() << "'";
  } catch (const E& e) {
    for (const std::string& f : fragments)
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << "message '" << e.what() << "' lacks '" << f << "'";
  }
}

template <class E = Error, class Fn>
void expectThrowsNaming(Fn fn, const std::string& fragment) {
  expectThrowsNaming<E>(fn, {fragment});
}

}  // namespace gssm::testing
