# SPDX-License-Identifier: MIT
# pour_warnings(target): the warning set every target of ours compiles with. Warnings are errors only with
# POUR_WERROR (scripts/test.sh, i.e. CI, turns it on through the presets): a newer compiler's new warning
# must not break a user's build.
option(POUR_WERROR "Treat warnings as errors (CI)" OFF)
function(pour_warnings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra $<$<BOOL:${POUR_WERROR}>:-Werror> -Wshadow -Wconversion -Wsign-conversion -Wdouble-promotion
    $<$<COMPILE_LANGUAGE:C>:-Wstrict-prototypes -Wmissing-prototypes>)
endfunction()
