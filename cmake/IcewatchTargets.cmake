# Common settings for every target the project owns. Warnings are errors here, never on
# third-party headers (those come in as SYSTEM includes through their imported targets).
# Link options are PUBLIC so that a sanitizer reaches every executable linking our libraries.
function(icewatch_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wnon-virtual-dtor)
  # The fuzz build uses clang, whose warnings differ from the GCC that CI holds the code to.
  if(NOT ICEWATCH_FUZZ)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(ICEWATCH_FUZZ)
    # Coverage feedback for libFuzzer in every library the targets reach.
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
  if(ICEWATCH_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=${ICEWATCH_SANITIZE} -fno-omit-frame-pointer
                                             -fno-sanitize-recover=all)
    target_link_options(${target} PUBLIC -fsanitize=${ICEWATCH_SANITIZE})
  endif()
endfunction()
