# Checks that the integration snippet of the Markdown file README (docs/library.md: the C++ block
# after "<!-- integration-core -->") is the region of examples/integrate.cpp between
# "// [integration-core]" and "// [integration-core-end]", so the manual shows code that compiles
# and runs in the test suite.
file(READ ${EXAMPLE} example)
string(REGEX MATCH "// \\[integration-core\\]\n(.*)\n[ ]*// \\[integration-core-end\\]" _ "${example}")
set(core "${CMAKE_MATCH_1}")
if(core STREQUAL "")
  message(FATAL_ERROR "${EXAMPLE} has no // [integration-core] ... // [integration-core-end] region")
endif()
string(REGEX REPLACE "(^|\n)  " "\\1" core "${core}")  # the example's indent of main()
file(READ ${README} readme)
string(REGEX MATCH "<!-- integration-core -->\n```cpp\n(.*)\n```\n<!-- integration-core-end -->" _ "${readme}")
set(snippet "${CMAKE_MATCH_1}")
if(snippet STREQUAL "")
  message(FATAL_ERROR "${README} has no <!-- integration-core --> ```cpp ... ``` <!-- integration-core-end --> block")
endif()
if(NOT snippet STREQUAL core)
  message(FATAL_ERROR "${README}'s integration snippet differs from examples/integrate.cpp's core:\n--- ${README}\n${snippet}\n--- example\n${core}")
endif()
string(REGEX MATCHALL "\n" lines "${core}")
list(LENGTH lines n)
math(EXPR n "${n} + 1")
message("${README} integration snippet = examples/integrate.cpp core (${n} lines)")
