#pragma once
// The project's rule for bad input, as a test states it: the call throws InputError with a
// one-line message (no '\n', no '\r') holding every key word.
#include <gtest/gtest.h>

#include <functional>
#include <initializer_list>
#include <string>

#include "shadowfilter/errors.hpp"

namespace sf::test {

inline void expect_input_error(const std::function<void()>& call, std::initializer_list<std::string> key_words) {
  try {
    call();
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.find('\r'), std::string::npos) << message;
    for (const std::string& word : key_words)
      EXPECT_NE(message.find(word), std::string::npos) << "missing '" << word << "' in: " << message;
  }
}

}  // namespace sf::test
