// The SPARQL editor: Ctrl+Enter (or Cmd+Enter) runs the query, Tab indents, and choosing a named query
// puts its text in the editor without leaving the page. Without this script the page still works.
(function () {
  "use strict";
  const form = document.getElementById("sparql-form");
  const editor = document.getElementById("query");
  if (!form || !editor) return;
  const texts = JSON.parse(document.getElementById("example-texts").textContent);
  const links = Array.from(document.querySelectorAll("a[data-example]"));

  editor.addEventListener("keydown", function (event) {
    if (event.key === "Enter" && (event.ctrlKey || event.metaKey)) {
      event.preventDefault();
      form.requestSubmit ? form.requestSubmit() : form.submit();
    } else if (event.key === "Tab" && !event.shiftKey && !event.altKey && !event.ctrlKey) {
      event.preventDefault(); // indent; Esc then Tab leaves the editor for keyboard users
      editor.setRangeText("  ", editor.selectionStart, editor.selectionEnd, "end");
    } else if (event.key === "Escape") {
      editor.blur();
    }
  });

  links.forEach(function (link, index) {
    link.addEventListener("click", function (event) {
      if (event.ctrlKey || event.metaKey || event.shiftKey || event.button !== 0) return; // new tab: follow it
      event.preventDefault();
      editor.value = texts[index];
      links.forEach((other) => other.removeAttribute("aria-current"));
      link.setAttribute("aria-current", "true");
      editor.focus();
      editor.setSelectionRange(0, 0);
      editor.scrollTop = 0;
    });
  });
})();
