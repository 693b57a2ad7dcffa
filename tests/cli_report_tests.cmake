# report.html in a browser (issue 20): kartograf map on a small synthetic sequence, then headless
# Chromium (Debian's chromium; scripts/install-deps.sh) loads the page with software WebGL
# (SwiftShader). The page checks itself (src/io/map_report_html.hpp): it fails on any script or
# console error, a picture that does not load, or a 3-D view that is not drawn. A copy with a
# picture removed and a broken script shows that those checks catch both. No Chromium: failure.
add_test(NAME Cli.report_renders_in_chromium
  COMMAND sh -c [=[
rm -rf "$1" || exit 1
command -v chromium > /dev/null || { echo "FAIL: chromium is not installed (scripts/install-deps.sh)"; exit 1; }
"$0" synth --out "$1/seq" --frames 30 --width 320 --height 240 > /dev/null 2>&1 || { echo "FAIL: synth"; exit 1; }
"$0" map "$1/seq" --out "$1/map" --backend cpu --no-progress > "$1/map.log" 2>&1 || { cat "$1/map.log"; exit 1; }
# Prints the loaded page's <html> element (with the page's check attributes) to stdout.
render() {
  timeout 120 chromium --headless=new --no-sandbox --disable-gpu --disable-dev-shm-usage --use-angle=swiftshader \
    --enable-unsafe-swiftshader --user-data-dir="$1/profile" --enable-logging=stderr --v=0 \
    --window-size=1280,2000 --virtual-time-budget=10000 --dump-dom "file://$2" \
    > "$2.dom" 2> "$2.log" || { tail -20 "$2.log"; echo "FAIL: chromium on $2"; return 1; }
  grep -o '<html[^>]*>' "$2.dom" | head -1
}
root=$(render "$1" "$1/map/report.html") || exit 1
echo "report.html: $root"
case "$root" in *data-errors=*) echo "FAIL: script errors"; exit 1;; esac
case "$root" in *'data-images="ok '[1-9]*) ;; *) echo "FAIL: a picture did not load"; exit 1;; esac
case "$root" in *'data-scene="ok '*) ;; *) echo "FAIL: the 3-D view was not drawn"; exit 1;; esac
grep -q "evaluation.png" "$1/map/report.html" || { echo "FAIL: evaluation.png is not shown"; exit 1; }
cp -r "$1/map" "$1/broken" && rm "$1/broken/rooms.png" || exit 1
sed -i 's|</main>|</main><script>no_such_function();</script>|' "$1/broken/report.html" || exit 1
root=$(render "$1" "$1/broken/report.html") || exit 1
echo "broken copy: $root"
case "$root" in *'data-images="missing: rooms.png"'*) ;; *) echo "FAIL: the missing picture was not caught"; exit 1;; esac
case "$root" in *'data-errors="script error: '*no_such_function*) ;; *) echo "FAIL: the script error was not caught"; exit 1;; esac
exit 0
]=] $<TARGET_FILE:kartograf> ${CMAKE_BINARY_DIR}/cli-report)
set_tests_properties(Cli.report_renders_in_chromium PROPERTIES TIMEOUT 300)
