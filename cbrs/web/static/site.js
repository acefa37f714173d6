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
  // A phone's header: the pages' links behind the Menu button, so that the header keeps to one line at
  // 375 px (they took four). Only with this script: without it the button stays hidden and the links show.
  const header = document.querySelector("header.top");
  const toggle = document.getElementById("menu-toggle");
  if (header && toggle) {
    const show = (open) => {
      header.classList.toggle("open", open);
      toggle.setAttribute("aria-expanded", String(open));
    };
    const nav = header.querySelector("nav");
    if (nav) {
      nav.id = nav.id || "site-nav";
      toggle.setAttribute("aria-controls", nav.id);
    }
    header.classList.add("menu");
    toggle.addEventListener("click", () => show(!header.classList.contains("open")));
    header.addEventListener("keydown", (event) => {
      if (event.key !== "Escape" || !header.classList.contains("open")) return;
      show(false);
      toggle.focus();
    });
  }
  // A picture wider than the page opens on its middle, where the class or the plan's trunk is drawn,
  // not on its empty left edge.
  for (const scroller of document.querySelectorAll(".diagram-scroll")) {
    scroller.scrollLeft = (scroller.scrollWidth - scroller.clientWidth) / 2;
  }
})();
