// The tasks page, live: follows /tasks/events (server-sent events) and keeps the step table, the event
// list, the status badge, the camera's frame counter and the recent runs current; a run's page follows a
// queued run (its place in line) until it starts, then the run. No dependencies.
(function () {
  "use strict";
  const live = document.getElementById("live");
  if (!live || !window.EventSource) return;

  const follow = live.dataset.follow; // "latest", or the id of the run this page shows
  const prefixes = JSON.parse(live.dataset.prefixes || "{}");
  const resource = live.dataset.resource;
  const byId = (id) => document.getElementById(id);
  const steps = byId("steps");
  const eventList = byId("event-list");
  const badge = byId("run-status");
  const runName = byId("run-name");
  const verdict = byId("verdict");
  const frameCount = byId("frame");
  const camera = byId("camera");
  const streamState = byId("stream-state");
  let current = live.dataset.run || null;
  const MAX_EVENTS = 300;

  function shorten(iri) {
    let best = "";
    for (const [prefix, namespace] of Object.entries(prefixes)) {
      if (iri.startsWith(namespace) && namespace.length > (prefixes[best] || "").length) best = prefix;
    }
    const local = best ? iri.slice(prefixes[best].length) : "";
    return local && /^[\w.-]+$/.test(local) ? best + ":" + local : iri;
  }

  // IRIs inside a reason read as the components beside them do (links.short_text on the server).
  const shortenText = (text) => text.replace(/https?:\/\/[^\s<>"']*[^\s<>"'.,;:)\]]/g, shorten);

  function el(tag, attrs, ...children) {
    const node = document.createElement(tag);
    for (const [name, value] of Object.entries(attrs || {})) node.setAttribute(name, value);
    for (const child of children) node.append(child);
    return node;
  }

  function iriLink(iri) {
    if (!resource) return el("span", { title: iri }, shorten(iri));
    return el("a", { href: resource + "?iri=" + encodeURIComponent(iri), title: iri }, shorten(iri));
  }

  function setBadge(status, inLine) {
    badge.textContent = status;
    badge.className = "badge status-" + status;
    live.dataset.status = status;
    const place = byId("in-line");
    if (place) {
      place.textContent = status === "queued" ? inLine || "" : "";
      place.hidden = status !== "queued";
    }
    const stop = byId("cancel");
    if (stop) {
      stop.hidden = status !== "running" && status !== "queued";
      if (current) stop.action = live.dataset.runs + "/" + encodeURIComponent(current) + "/cancel";
    }
  }

  // One row per plan step, as the server's steps() builds them (cbrs/web/tasks.py): the components tried
  // in order, the outcome, and every failure's reason, kept after a failover succeeds; after a re-plan the
  // new plan's steps follow the old one's. Rows the server rendered carry their plan and what they show.
  let plan = Number((steps.lastElementChild || {}).dataset?.plan) || 1;
  const STEP_STATUS = { step_started: "started", step_succeeded: "succeeded", step_failed: "failed" };

  function row(step) {
    const key = 'tr[data-plan="' + plan + '"][data-step="' + step + '"]';
    let tr = steps.querySelector(key);
    if (!tr) {
      const num = el("td", { class: "num" });
      if (plan > 1) num.append(el("span", { class: "small muted", title: "plan " + plan + ", after a re-plan" }, plan + "."));
      num.append(String(step));
      tr = el("tr", { "data-plan": String(plan), "data-step": String(step) }, num, el("td"), el("td"));
      steps.append(tr);
    }
    if (!tr.tried) {
      tr.tried = Array.from(tr.querySelectorAll("td:nth-child(2) [title]"), (a) => a.title);
      tr.reasons = Array.from(tr.querySelectorAll("td:nth-child(3) .small"), (s) => s.textContent);
      tr.failover = tr.classList.contains("failover");
    }
    return tr;
  }

  function stepEvent(message) {
    if (message.event === "replanning") plan = Number(message.plan) || plan + 1;
    const status = STEP_STATUS[message.event];
    if (!status) return; // the progress events that are no step's: awaiting, passed_over, base_chosen
    const tr = row(message.step);
    const [, who, state] = tr.children;
    if (status === "started" && !tr.tried.includes(message.component)) {
      tr.tried.push(message.component);
      who.replaceChildren();
      tr.tried.forEach((iri, i) => {
        if (i) who.append(" ", el("span", { class: "arrow", "aria-label": "failed over to" }, "→"), " ");
        who.append(iriLink(iri));
      });
    }
    if (status === "failed") {
      tr.reasons.push(shortenText(message.reason || ""));
      tr.failover = Boolean(message.failover);
    }
    state.replaceChildren(el("span", { class: "badge status-" + status }, status));
    for (const reason of tr.reasons) if (reason) state.append(el("br"), el("span", { class: "small muted" }, reason));
    tr.className = "step-" + status + (tr.tried.length > 1 || tr.failover ? " failover" : "");
  }

  function listEvent(message) {
    const parts = [el("code", {}, message.topic || ""), " " + (message.event || message.state || message.status || "")];
    if (message.step) parts.push(" · step " + message.step);
    if (message.component) parts.push(" · " + shorten(message.component));
    if (message.reason) parts.push(" · ", el("span", { class: "muted" }, shortenText(message.reason)));
    if (message.failover) parts.push(" · failover to " + shorten(message.failover));
    eventList.prepend(el("li", {}, ...parts));
    while (eventList.children.length > MAX_EVENTS) eventList.lastChild.remove();
  }

  function startRun(id, task) {
    current = id;
    plan = 1;
    steps.replaceChildren();
    eventList.replaceChildren();
    verdict.textContent = "";
    runName.replaceChildren(el("a", { href: live.dataset.runs + "/" + id }, id), " · " + shorten(task));
    setBadge("running");
    restartCamera();
  }

  // The camera is a stream (MJPEG) while the server has a stream slot for it; refused (all slots taken: a
  // class of twenty pages open at once), it is the still of the latest frame, asked for when the events or
  // the page's checks say a newer one exists (camera.jpg?frame=N answers at once, asking the run for none).
  let stills = false;
  camera.addEventListener("error", () => {
    if (stills) return;
    stills = true;
    camera.src = live.dataset.still + "?frame=" + Number(frameCount.dataset.frame || 0) + "&t=" + Date.now();
  });

  function restartCamera() {
    // The stream ends by itself when idle; a new run deserves a fresh one (and a slot may be free again).
    stills = false;
    camera.src = live.dataset.stream + "?t=" + Date.now();
  }

  function showFrame(number) {
    if (number > Number(frameCount.dataset.frame || 0)) {
      frameCount.dataset.frame = String(number);
      frameCount.textContent = String(number);
      if (stills) camera.src = live.dataset.still + "?frame=" + number;
    }
  }

  async function refreshRuns() {
    const response = await fetch(live.dataset.runs + ".json", { headers: { Accept: "application/json" } });
    if (!response.ok) return;
    const data = await response.json();
    const body = byId("runs");
    if (!body) return;
    body.replaceChildren(
      ...data.runs.map((r) =>
        el(
          "tr",
          {},
          el("td", {}, el("a", { href: r.url }, r.id)),
          el("td", {}, r.shown || r.task),
          el("td", { class: "num" }, String(r.seed)),
          el("td", {}, r.faults.join(", ") || "–"),
          el("td", {}, el("span", { class: "badge status-" + r.status }, r.status), r.in_line ? el("span", { class: "muted small" }, " " + r.in_line) : ""),
          el("td", { class: "num" }, r.finished ? (r.finished - r.started).toFixed(1) : "…"),
        ),
      ),
    );
  }

  async function catchUp(id) {
    // Events sent before this page subscribed: rebuild the table and the list from the run's record.
    const response = await fetch(live.dataset.runs + "/" + encodeURIComponent(id) + ".json");
    if (!response.ok) return;
    const run = (await response.json()).run; // the run page's twin: {mode, run}
    if (current !== id) startRun(id, run.shown || run.task);
    plan = 1;
    steps.replaceChildren();
    eventList.replaceChildren();
    run.events.forEach(handleRunEvent);
    setBadge(run.status, run.in_line);
    if (run.verdict) verdict.textContent = shortenText(run.verdict);
  }

  async function followQueued() {
    // A queued run's page: the runs before it started or ended, so its place in line changed (or it left).
    const response = await fetch(live.dataset.runs + "/" + encodeURIComponent(current) + ".json");
    if (!response.ok) return;
    const run = (await response.json()).run;
    if (run && run.id === current && run.status === "queued") setBadge(run.status, run.in_line);
  }

  async function showVerdict(id) {
    // A run that made no plan or broke publishes no /cbrs/task verdict: its record says why.
    const response = await fetch(live.dataset.runs + "/" + encodeURIComponent(id) + ".json");
    if (!response.ok) return;
    const run = (await response.json()).run;
    if (run && run.verdict && current === id) verdict.textContent = shortenText(run.verdict);
  }

  function handleRunEvent(message) {
    if (message.topic === "/cbrs/task_progress") stepEvent(message);
    if (message.topic === "/cbrs/task") verdict.textContent = message.status + (message.reason ? ": " + shortenText(message.reason) : "");
    if (message.event === "run_finished") {
      setBadge(message.status);
      if (!verdict.textContent) showVerdict(message.run);
    }
    listEvent(message);
  }

  function handle(message) {
    if (message.event === "hello") {
      showFrame(message.frame);
      const mine = follow === "latest" || follow === message.active;
      if (message.active && mine) catchUp(message.active);
      else if ((live.dataset.status === "running" || live.dataset.status === "queued") && current) catchUp(current); // it started or ended while we were away
      return;
    }
    if (message.event === "frame") return showFrame(message.frame);
    if (message.event === "store_updated") return;
    if (message.event === "run_started" && (follow === "latest" || follow === message.run)) {
      startRun(message.run, message.shown || message.task); // the pages' name (lab10:SwitchOnTheReadingLamp)
    }
    if (message.run !== current) {
      if (message.event === "run_queued" || message.event === "run_finished") refreshRuns(); // the queue changed
      if (live.dataset.status === "queued" && /^run_/.test(message.event || "")) followQueued();
      return;
    }
    handleRunEvent(message);
    if (message.event === "run_finished") refreshRuns();
  }

  // Without a stream (the server refused it: every stream slot taken, 503), the page asks for the run's JSON
  // every POLL_MS and redraws what changed, and tries the stream again every RETRY_MS: an EventSource that
  // is refused does not reconnect by itself, and the page sat at "running" with an empty steps table.
  const POLL_MS = 2000;
  const RETRY_MS = 20000;
  let polling = null;
  let seen = -1; // events of the current run already drawn by a check

  function applyRun(run) {
    if (run.id !== current) {
      startRun(run.id, run.shown || run.task);
      seen = -1;
    }
    if (run.events.length !== seen || live.dataset.status !== run.status) {
      seen = run.events.length;
      plan = 1;
      steps.replaceChildren();
      eventList.replaceChildren();
      verdict.textContent = "";
      run.events.forEach((message) => {
        if (message.topic === "/cbrs/task_progress") stepEvent(message);
        listEvent(message);
      });
      const was = live.dataset.status;
      const ended = (was === "running" || was === "queued") && run.status !== "running" && run.status !== "queued";
      setBadge(run.status, run.in_line);
      if (run.verdict) verdict.textContent = shortenText(run.verdict);
      if (ended) refreshRuns();
    }
  }

  async function check() {
    const url = follow === "latest" ? live.dataset.runs + ".json" : live.dataset.runs + "/" + encodeURIComponent(follow) + ".json";
    try {
      const response = await fetch(url, { headers: { Accept: "application/json" } });
      if (!response.ok) return;
      const data = await response.json();
      const run = follow === "latest" ? data.active : data.run;
      if (run) applyRun(run);
      if (data.camera) showFrame(data.camera.frame);
    } catch (error) {
      streamState.textContent = "· the server does not answer; checking again";
    }
  }

  function startPolling() {
    if (polling) return;
    streamState.textContent = "· the server's live streams are all in use (many pages follow runs): this page checks every " + POLL_MS / 1000 + " s instead";
    seen = -1;
    check();
    polling = setInterval(check, POLL_MS);
    setTimeout(connect, RETRY_MS);
  }

  function stopPolling() {
    if (!polling) return;
    clearInterval(polling);
    polling = null;
  }

  function connect() {
    const source = new EventSource(live.dataset.events);
    source.onopen = () => {
      stopPolling();
      streamState.textContent = "· live";
    };
    source.onerror = () => {
      if (source.readyState === EventSource.CLOSED) {
        if (polling) setTimeout(connect, RETRY_MS);
        else startPolling();
      } else streamState.textContent = "· reconnecting…";
    };
    source.onmessage = (event) => handle(JSON.parse(event.data));
    source.addEventListener("end", () => (streamState.textContent = "· paused, reconnecting…"));
  }
  connect();

  // Stop the run shown without leaving the page; the form still works without this script.
  const stopForm = byId("cancel");
  if (stopForm) {
    stopForm.addEventListener("submit", async (event) => {
      event.preventDefault();
      const button = byId("cancel-button");
      button.disabled = true;
      try {
        const response = await fetch(stopForm.action + ".json", {
          method: "POST",
          body: new URLSearchParams(new FormData(stopForm)), // the token typed, for a run another computer started
        });
        const data = await response.json();
        stopForm.parentElement.querySelectorAll(".form-message").forEach((node) => node.remove());
        const box = response.status === 202 ? "ok-box" : "error-box";
        stopForm.before(el("p", { class: box + " form-message", role: "status" }, data.message || response.statusText));
      } finally {
        button.disabled = false;
      }
    });
  }

  // Start a run without leaving the page; the form still works without this script.
  const form = byId("start");
  if (form) {
    form.addEventListener("submit", async (event) => {
      event.preventDefault();
      const button = byId("start-button");
      button.disabled = true;
      form.parentElement.querySelectorAll(".field-error, .form-message").forEach((node) => node.remove());
      try {
        const response = await fetch(form.action + ".json", {
          method: "POST",
          body: new URLSearchParams(new FormData(form)),
        });
        const data = await response.json();
        let note;
        if (response.status === 202 && data.started.status === "queued") {
          // it waits its turn: the page goes on following the run going, and its own page follows it
          note = el("p", { class: "ok-box form-message", role: "status" }, data.message + "; ", el("a", { href: data.started.page }, "its own page"), ".");
          refreshRuns();
        } else if (response.status === 202) {
          startRun(data.started.id, data.started.shown || data.started.task);
          note = el("p", { class: "ok-box form-message", role: "status" }, data.message);
        } else if (data.fields) {
          for (const [name, text] of Object.entries(data.fields)) {
            const field = byId(name);
            if (field) field.after(el("span", { class: "field-error", id: name + "-error", role: "alert" }, text));
          }
        } else {
          // as the page words a refused Start (tasks.html): the run going, and what to do
          const said = data.running
            ? [data.message + ": follow ", el("a", { href: live.dataset.runs + "/" + data.running }, data.running), ", then start again."]
            : [data.message];
          note = el("p", { class: "error-box form-message", role: "alert" }, ...said);
        }
        if (note) form.before(note);
      } finally {
        button.disabled = false;
      }
    });
  }
})();
