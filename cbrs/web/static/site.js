// Every page: "/" jumps to a search box (this page's own, else the header's), as on most sites
// with a search; not while typing in a field.
(function () {
  document.addEventListener("keydown", function (event) {
    if (event.key !== "/" || event.ctrlKey || event.metaKey || event.altKey) return;
    const target = event.target;
    if (target.closest && target.closest("input, textarea, select, [contenteditable]")) return;
    const box = document.querySelector("main input[type=search]") || document.getElementById("site-search");
    if (!box) return;
    event.preventDefault();
    box.focus();
    box.select();
  });
  // A picture wider than the page opens on its middle, where the class or the plan's trunk is drawn,
  // not on its empty left edge.
  for (const scroller of document.querySelectorAll(".diagram-scroll")) {
    scroller.scrollLeft = (scroller.scrollWidth - scroller.clientWidth) / 2;
  }
})();
