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
  // The header keeps to one line at every width: the pages' links go behind the Menu button where they do
  // not fit on it (at 375 px they took four lines, between 641 and about 1,220 px two or three). Whether
  // they fit is measured, not guessed from a width: laid out in full, every item of the header must share
  // one row, whatever the fonts. Only with this script: without it the button stays hidden and the links
  // show, wrapping as they must.
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
    const items = () => Array.from(header.querySelectorAll(":scope > a, :scope > form, nav a"));
    const oneRow = () => {
      const boxes = items()
        .map((item) => item.getBoundingClientRect())
        .filter((box) => box.width > 0);
      return Math.max(...boxes.map((box) => box.top)) < Math.min(...boxes.map((box) => box.bottom));
    };
    const fit = () => {
      header.classList.remove("collapsed"); // laid out in full, measured, folded again if need be: one paint
      const fits = oneRow();
      header.classList.toggle("collapsed", !fits);
      if (fits && header.classList.contains("open")) show(false);
    };
    fit();
    window.addEventListener("resize", fit); // dispatched once a frame, before it is drawn
    if (document.fonts) document.fonts.ready.then(fit); // a late font changes the links' widths
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
