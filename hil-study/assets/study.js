// The participant's page of the workload study. The server decides what
// comes next (it runs the task clock); the page shows it, sends answers,
// and repeats a send until the server has confirmed it is saved.
(function () {
  "use strict";
  const $ = (id) => document.getElementById(id);
  let state = null;
  let shownKey = "";
  let shownDistraction = "";
  let box = { x0: 0.4, y0: 0.4, x1: 0.6, y1: 0.6 };
  let boxSet = false;

  function keyOf(v) {
    const c = v.condition ? v.condition.id : "";
    const q = v.query ? "q" + v.query.number : "";
    const s = v.survey ? "s" + v.survey.query : "";
    return [v.phase, c, q, s].join("|");
  }

  async function post(path, body) {
    // Retried until the server answers: a save is never silently lost.
    for (let attempt = 0; ; attempt++) {
      try {
        const r = await fetch(path, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
        const v = await r.json().catch(() => ({}));
        if (r.ok) { $("error").textContent = ""; return true; }
        if (r.status >= 500 || r.status === 503) throw new Error(v.error || ("status " + r.status));
        $("error").textContent = v.error || ("Not accepted (" + r.status + ")");
        return false;
      } catch (e) {
        $("error").textContent = "Saving… (the connection is interrupted; trying again)";
        await new Promise((res) => setTimeout(res, Math.min(5000, 300 * (attempt + 1))));
      }
    }
  }

  async function poll() {
    try {
      const r = await fetch("api/state", { cache: "no-store" });
      if (r.ok) {
        const v = await r.json();
        state = v;
        render(v);
      }
    } catch (e) {
      $("status").textContent = "Reconnecting…";
    }
    setTimeout(poll, 250);
  }

  function setHidden(id, hidden) { $(id).hidden = hidden; }

  function render(v) {
    const key = keyOf(v);
    updateClock(v);
    if (v.distraction && v.distraction.type === "transcription") $("passage").textContent = v.distraction.words.join(" ");
    const dkey = v.distraction ? v.condition.id + "|" + v.distraction.index : "";
    if (key === shownKey) {
      // Only the distraction task moved on (a sum answered, a line sent).
      if (v.phase === "task" && dkey !== shownDistraction) { shownDistraction = dkey; showTask(v); }
      return;
    }
    shownKey = key;
    shownDistraction = dkey;
    $("error").textContent = "";
    ["intro", "query", "task", "survey", "done"].forEach((s) => setHidden(s, true));
    if (v.phase === "done") {
      setHidden("done", false);
      $("status").textContent = "Finished. Thank you!";
      scan.restart();
      return;
    }
    const c = v.condition;
    const part = "Part " + c.number + " of " + c.of;
    if (v.phase === "intro") {
      $("intro-title").textContent = part;
      const task = { none: "There is no other task in this part.", easy: "Add the numbers you are shown, as many as you comfortably can.",
        hard: "Copy the words of a passage as they appear." }[c.distraction];
      $("intro-text").textContent = task + (c.queries ? " Now and then the robot will ask you a question: answer it, then say how it felt."
        : " The robot will not ask questions in this part. At the end you will say how it felt.");
      setHidden("intro", false);
      $("status").textContent = part + ": ready when you are.";
      $("start").focus();
    } else if (v.phase === "task") {
      setHidden("task", false);
      showTask(v);
      if (v.query) {
        showQuery(v.query);
        setHidden("query", false);
        $("status").textContent = part + ": the robot has a question.";
        const first = document.querySelector("#query fieldset:not([hidden]) button, #query fieldset:not([hidden]) textarea, #query fieldset:not([hidden]) canvas");
        $("query-question").setAttribute("tabindex", "-1");
        (first || $("query-question")).focus();
      } else {
        $("status").textContent = part + ": working.";
      }
    } else if (v.phase === "survey") {
      showSurvey(v);
      setHidden("survey", false);
      $("status").textContent = part + ": a few questions about how it felt.";
      const first = document.querySelector("#survey-questions input");
      if (first) first.focus();
    }
    scan.restart();
  }

  function updateClock(v) {
    if (v.phase !== "task") return;
    const left = Math.max(0, v.duration_s - v.task_s);
    $("clock").textContent = v.condition.queries ? "" : ("About " + Math.ceil(left / 60) + " min left in this part.");
  }

  function showTask(v) {
    const d = v.distraction;
    setHidden("addition", d.type !== "addition");
    setHidden("transcription", d.type !== "transcription");
    setHidden("no-task", d.type !== "none");
    if (d.type === "addition") {
      $("sum-question").textContent = "What is " + d.a + " + " + d.b + "?";
      $("sum-answer").value = "";
      if (!v.query) $("sum-answer").focus();
    }
    if (d.type === "transcription") {
      $("transcript").value = "";
      if (!v.query) $("transcript").focus();
    }
  }

  function showQuery(q) {
    $("query-question").textContent = q.question;
    const pics = $("query-pictures");
    pics.textContent = "";
    ["q-mcq", "q-box", "q-text"].forEach((id) => setHidden(id, true));
    if (q.kind !== "bounding_box") {
      q.pictures.forEach((src, i) => {
        const f = document.createElement("figure");
        if (q.pictures.length > 1) {
          const cap = document.createElement("figcaption");
          cap.textContent = i === 0 ? "Left" : "Right";
          f.appendChild(cap);
        }
        const img = document.createElement("img");
        img.src = src; img.alt = q.alt[i];
        f.appendChild(img); pics.appendChild(f);
      });
    }
    if (q.kind === "mcq") {
      const box = $("q-options");
      box.textContent = "";
      q.options.forEach((o, i) => {
        const b = document.createElement("button");
        b.type = "button"; b.className = "choice"; b.id = "option-" + i;
        b.textContent = o.charAt(0).toUpperCase() + o.slice(1);
        b.addEventListener("click", () => answer({ type: "label", label: o }));
        box.appendChild(b);
      });
      setHidden("q-mcq", false);
    } else if (q.kind === "bounding_box") {
      $("box-image").src = q.pictures[0];
      $("box-image").alt = q.alt[0];
      box = { x0: 0.4, y0: 0.4, x1: 0.6, y1: 0.6 }; boxSet = false;
      setHidden("q-box", false);
      draw();
    } else {
      $("q-text-answer").value = "";
      setHidden("q-text", false);
    }
  }

  async function answer(a) {
    const v = state;
    if (!v || !v.query) return;
    if (await post("api/answer", { condition: v.condition.id, query: v.query.number, answer: a })) shownKey = "";
  }

  function showSurvey(v) {
    const qs = $("survey-questions");
    qs.textContent = "";
    $("survey-about").textContent = v.survey.query === null ? "About this whole part:" : "About the robot's question and your task just now:";
    v.survey.questions.forEach((q) => {
      const fs = document.createElement("fieldset");
      fs.className = "tlx";
      const lg = document.createElement("legend");
      lg.textContent = q.text; lg.id = "tlx-" + q.key + "-legend";
      fs.appendChild(lg);
      const scale = document.createElement("div");
      scale.className = "scale"; scale.setAttribute("role", "radiogroup"); scale.setAttribute("aria-labelledby", lg.id);
      for (let i = 1; i <= 5; i++) {
        const label = document.createElement("label");
        const input = document.createElement("input");
        input.type = "radio"; input.name = "tlx-" + q.key; input.value = String(i); input.id = "tlx-" + q.key + "-" + i;
        input.setAttribute("aria-label", i + (i === 1 ? " (" + q.low + ")" : i === 5 ? " (" + q.high + ")" : ""));
        const span = document.createElement("span");
        span.textContent = String(i);
        label.appendChild(input); label.appendChild(span);
        scale.appendChild(label);
      }
      fs.appendChild(scale);
      const anchors = document.createElement("div");
      anchors.className = "anchors";
      const lo = document.createElement("span"); lo.textContent = "1 = " + q.low;
      const hi = document.createElement("span"); hi.textContent = "5 = " + q.high;
      anchors.appendChild(lo); anchors.appendChild(hi);
      fs.appendChild(anchors);
      qs.appendChild(fs);
    });
  }

  async function sendSurvey() {
    const v = state;
    if (!v || !v.survey) return;
    const tlx = {};
    for (const q of v.survey.questions) {
      const checked = document.querySelector('input[name="tlx-' + q.key + '"]:checked');
      if (!checked) { $("error").textContent = "Please answer every question (" + q.text + ")"; return; }
      tlx[q.key] = parseInt(checked.value, 10);
    }
    if (await post("api/survey", { condition: v.condition.id, query: v.survey.query, tlx: tlx })) shownKey = "";
  }

  async function sendDistraction(text) {
    const v = state;
    if (!v || !v.distraction || text.trim() === "") return;
    const ok = await post("api/distraction", { condition: v.condition.id, index: v.distraction.index, text: text });
    if (ok && v.distraction.type === "addition") $("sum-feedback").textContent = "Saved. Next sum.";
  }

  // ---- bounding box -------------------------------------------------------
  function draw() {
    const c = $("box-canvas"), g = c.getContext("2d");
    g.clearRect(0, 0, c.width, c.height);
    const x = box.x0 * c.width, y = box.y0 * c.height, w = (box.x1 - box.x0) * c.width, h = (box.y1 - box.y0) * c.height;
    g.lineWidth = 10; g.strokeStyle = "#ffd400"; g.strokeRect(x, y, w, h);
    g.lineWidth = 4; g.strokeStyle = "#000"; g.strokeRect(x, y, w, h);
    const pct = (f) => Math.round(f * 100);
    $("box-readout").textContent = "Box: left " + pct(box.x0) + "%, top " + pct(box.y0) + "%, right " + pct(box.x1) + "%, bottom " + pct(box.y1) + "%";
  }
  function setupBox() {
    const c = $("box-canvas");
    let start = null;
    const at = (ev) => { const r = c.getBoundingClientRect(); return [Math.min(1, Math.max(0, (ev.clientX - r.left) / r.width)), Math.min(1, Math.max(0, (ev.clientY - r.top) / r.height))]; };
    c.addEventListener("pointerdown", (ev) => { if (scanning()) return; start = at(ev); c.setPointerCapture(ev.pointerId); });
    c.addEventListener("pointermove", (ev) => {
      if (!start) return;
      const p = at(ev);
      box = { x0: Math.min(start[0], p[0]), y0: Math.min(start[1], p[1]), x1: Math.max(start[0], p[0]), y1: Math.max(start[1], p[1]) };
      boxSet = true; draw();
    });
    c.addEventListener("pointerup", () => { start = null; });
    c.addEventListener("keydown", (ev) => {
      const d = 0.02, k = ev.key;
      const move = { ArrowLeft: [-d, 0], ArrowRight: [d, 0], ArrowUp: [0, -d], ArrowDown: [0, d] }[k];
      if (!move) return;
      ev.preventDefault();
      if (ev.shiftKey) { box.x1 = Math.min(1, Math.max(box.x0 + d, box.x1 + move[0])); box.y1 = Math.min(1, Math.max(box.y0 + d, box.y1 + move[1])); }
      else {
        const w = box.x1 - box.x0, h = box.y1 - box.y0;
        box.x0 = Math.min(1 - w, Math.max(0, box.x0 + move[0])); box.y0 = Math.min(1 - h, Math.max(0, box.y0 + move[1]));
        box.x1 = box.x0 + w; box.y1 = box.y0 + h;
      }
      box = { x0: +box.x0.toFixed(4), y0: +box.y0.toFixed(4), x1: +box.x1.toFixed(4), y1: +box.y1.toFixed(4) };
      boxSet = true; draw();
    });
    const names = ["Top left", "Top middle", "Top right", "Middle left", "Centre", "Middle right", "Bottom left", "Bottom middle", "Bottom right"];
    names.forEach((n, i) => {
      const b = document.createElement("button");
      b.type = "button"; b.className = "region"; b.id = "region-" + i; b.textContent = n;
      b.addEventListener("click", () => {
        const cx = i % 3, cy = Math.floor(i / 3);
        box = { x0: cx / 3, y0: cy / 3, x1: (cx + 1) / 3, y1: (cy + 1) / 3 }; boxSet = true; draw();
      });
      $("regions").appendChild(b);
    });
    $("send-box").addEventListener("click", () => {
      if (!boxSet) { $("error").textContent = "Draw a box or pick a region first, or choose \"I don't know\"."; return; }
      answer({ type: "bounding_box", bbox: box });
    });
  }

  // ---- single-switch scanning (scan.js) ----------------------------------
  // As on the robot's query page: the highlight steps through the visible
  // controls of the part on screen.
  function controls() {
    const sel = "main section:not([hidden]) button, main section:not([hidden]) input, main section:not([hidden]) textarea";
    return Array.from(document.querySelectorAll(sel)).filter((e) => !e.disabled && e.offsetParent !== null && !e.closest("[hidden]"));
  }
  const scan = hilScan({ controls: controls });
  const scanning = scan.scanning;

  document.addEventListener("DOMContentLoaded", () => {
    setupBox();
    $("start").addEventListener("click", async () => {
      if (state && await post("api/start", { condition: state.condition.id })) shownKey = "";
    });
    $("q-decline").addEventListener("click", () => answer({ type: "declined" }));
    $("send-text").addEventListener("click", () => {
      const t = $("q-text-answer").value.trim();
      if (!t) { $("error").textContent = "Type an answer first, or choose \"I don't know\"."; return; }
      answer({ type: "text", text: t });
    });
    $("survey-send").addEventListener("click", sendSurvey);
    $("sum-send").addEventListener("click", () => sendDistraction($("sum-answer").value));
    $("sum-answer").addEventListener("keydown", (ev) => { if (ev.key === "Enter") sendDistraction($("sum-answer").value); });
    $("transcript-send").addEventListener("click", () => { const t = $("transcript").value; sendDistraction(t).then(() => { $("transcript").value = ""; }); });
    $("transcript").addEventListener("keydown", (ev) => { if (ev.key === "Enter") { const t = $("transcript").value; sendDistraction(t).then(() => { $("transcript").value = ""; }); } });
    poll();
  });
})();
