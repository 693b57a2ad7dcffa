// report.html checks itself (it runs first, in <head>): every script error and console error is
// listed in <html data-errors>, and once the page has loaded <html data-images> says "ok N" or
// names the pictures that did not load. A test reads both from the DOM (headless Chromium).
// It also keeps small grid pictures from being enlarged beyond legibility.
"use strict";
(function () {
  const root = document.documentElement;
  const errors = [];
  function note(text) {
    errors.push(text);
    root.setAttribute("data-errors", errors.join(" | "));
  }
  window.addEventListener("error", function (event) {
    note("script error: " + event.message + " (line " + event.lineno + ")");
  });
  window.addEventListener("unhandledrejection", function (event) {
    note("unhandled rejection: " + event.reason);
  });
  const consoleError = console.error;
  console.error = function () {
    note("console.error: " + Array.prototype.join.call(arguments, " "));
    consoleError.apply(console, arguments);
  };
  window.addEventListener("load", function () {
    // Grids are drawn a pixel or two per cell: enlarge them at most 3 times (their legends too).
    for (const image of document.querySelectorAll("figure.grid img"))
      image.style.maxWidth = 3 * image.naturalWidth + "px";
    const missing = [];
    for (const image of document.images)
      if (!image.complete || image.naturalWidth === 0) missing.push(image.getAttribute("src"));
    root.setAttribute("data-images",
                      missing.length ? "missing: " + missing.join(", ") : "ok " + document.images.length);
  });
})();
