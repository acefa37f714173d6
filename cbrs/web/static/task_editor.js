// The task editor: Ctrl+Enter (or Cmd+Enter) checks and plans the task, Tab indents, and a "line N" link
// beside a problem selects that line of the text. Without this script the page still works.
(function () {
  "use strict";
  const editor = document.getElementById("turtle");
  const check = document.getElementById("check-button");
  if (!editor || !check) return;

  editor.addEventListener("keydown", function (event) {
    if (event.key === "Enter" && (event.ctrlKey || event.metaKey)) {
      event.preventDefault();
      check.click(); // the form's action=check, as the button sends it
    } else if (event.key === "Tab" && !event.shiftKey && !event.altKey && !event.ctrlKey) {
      event.preventDefault(); // indent; Esc then Tab leaves the editor for keyboard users
      editor.setRangeText("    ", editor.selectionStart, editor.selectionEnd, "end");
    } else if (event.key === "Escape") {
      editor.blur();
    }
  });

  document.querySelectorAll("a[data-line]").forEach(function (link) {
    link.addEventListener("click", function (event) {
      event.preventDefault();
      const lines = editor.value.split("\n");
      const number = Math.min(Math.max(parseInt(link.dataset.line, 10), 1), lines.length);
      const start = lines.slice(0, number - 1).reduce((sum, line) => sum + line.length + 1, 0);
      editor.focus();
      editor.setSelectionRange(start, start + lines[number - 1].length);
      const height = editor.scrollHeight / Math.max(lines.length, 1);
      editor.scrollTop = Math.max(0, (number - 3) * height);
    });
  });
})();
