# sweetspot_warnings(TARGET): our warning set, applied per target (never to
# third-party code, whose headers come in as SYSTEM includes).
function(sweetspot_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow
                                           -Wnon-virtual-dtor -Wconversion-null)
endfunction()
