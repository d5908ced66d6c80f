# Builds the preview's page into the program (cmake -P, at build time, so an edit of the page
# rebuilds it): OUT gets engine/preview/page.html and app.js as raw string literals.
# -DPAGE=... -DSCRIPT=... -DOUT=...
file(READ ${PAGE} page)
file(READ ${SCRIPT} script)
foreach(text page script)
  string(FIND "${${text}}" ")streamrt_page\"" clash)
  if(NOT clash EQUAL -1)
    message(FATAL_ERROR "${text} holds the raw string's end marker )streamrt_page\"")
  endif()
endforeach()
file(WRITE ${OUT}.tmp "// Generated from engine/preview/page.html and app.js by engine/preview/embed_page.cmake.\n"
     "#include \"preview/serve.h\"\n"
     "namespace streamrt::preview {\n"
     "const char* const kPageHtml = R\"streamrt_page(${page})streamrt_page\";\n"
     "const char* const kPageScript = R\"streamrt_page(${script})streamrt_page\";\n"
     "}  // namespace streamrt::preview\n")
# Only a changed page touches the file (no rebuild of the program otherwise).
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different ${OUT}.tmp ${OUT})
file(REMOVE ${OUT}.tmp)
