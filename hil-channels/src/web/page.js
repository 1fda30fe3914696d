// The web channel's page: polls the open question, shows it, sends the
// answer. Plain JavaScript, no dependencies, nothing loaded from elsewhere.
"use strict";
(function () {
  const $ = (id) => document.getElementById(id);
  const POLL_MS = 800;
  let current = null;     // the open question, as served by api/query
  let box = null;         // [x0, y0, x1, y1] in 0..1
  let drag = null;
  let picture = null;     // the item's picture, when the server has one
  let sending = false;

  function setStatus(text) {
    if ($("status").textContent !== text) $("status").textContent = text;
  }

  async function poll() {
    try {
      const r = await fetch("api/query", { cache: "no-store" });
      if (!r.ok) throw new Error("status " + r.status);
      const q = await r.json();
      if (q.state === "query") {
        if (!current || current.id !== q.id) show(q);
        current.remaining_s = q.remaining_s;
        updateTimer();
      } else {
        if (current) hide();
        setStatus(q.notice || "Waiting: the robot has no question right now.");
      }
    } catch (e) {
      setStatus("Connection lost. Retrying…");
    }
    setTimeout(poll, POLL_MS);
  }

  function updateTimer() {
    if (!current) return;
    const s = Math.max(0, Math.round(current.remaining_s));
    $("timer").textContent = "Time left: " + Math.floor(s / 60) + ":" + String(s % 60).padStart(2, "0") +
      " (then the robot chooses on its own)";
  }

  function show(q) {
    current = q;
    $("error").textContent = "";
    $("kind").textContent = "Question type: " + q.kind_text;
    $("question").textContent = q.question;
    $("item").textContent = "Food: " + q.item.text;
    const img = $("item-image");
    picture = null;
    if (q.image) {
      img.alt = "Picture of the " + q.item.text;
      img.src = q.image;
      img.hidden = q.kind.response === "bounding_box";  // drawn on the canvas instead
      const p = new Image();
      p.onload = () => { picture = p; draw(); };
      p.src = q.image;
    } else {
      img.hidden = true;
      img.removeAttribute("src");
    }
    $("query").hidden = false;
    $("mcq").hidden = q.kind.response !== "mcq";
    $("bbox").hidden = q.kind.response !== "bounding_box";
    $("open").hidden = q.kind.response !== "open_ended";
    if (q.kind.response === "mcq") buildChoices(q);
    if (q.kind.response === "bounding_box") { box = null; syncInputs(); draw(); }
    if (q.kind.response === "open_ended") $("answer-text").value = "";
    setStatus("The robot asks: " + q.question);
    // Move focus to the first control so keyboard users start at the answer.
    const first = controls()[0];
    if (first) first.focus();
    scan.restart();
  }

  function hide() {
    current = null;
    $("query").hidden = true;
    scan.stop();
  }

  function buildChoices(q) {
    const area = $("choices");
    area.textContent = "";
    q.actions.forEach((a) => {
      const b = document.createElement("button");
      b.type = "button";
      b.className = "choice";
      b.id = "choice-" + a.arm;
      b.dataset.arm = a.arm;
      const name = document.createElement("span");
      name.textContent = a.name;
      b.appendChild(name);
      if (a.hint) {
        const h = document.createElement("span");
        h.className = "hint";
        h.textContent = a.hint;
        b.appendChild(h);
      }
      b.setAttribute("aria-label", a.name + (a.hint ? ": " + a.hint : ""));
      b.addEventListener("click", () => send({ type: "action", arm: a.arm }));
      area.appendChild(b);
    });
  }

  async function send(answer) {
    if (!current || sending) return;
    sending = true;
    $("error").textContent = "";
    try {
      const r = await fetch("api/answer", {
        method: "POST",
        headers: { "Content-Type": "application/json" },
        body: JSON.stringify({ id: current.id, answer: answer }),
      });
      if (r.ok) {
        hide();
        setStatus("Thank you. Sent.");
      } else {
        let msg = "The answer was not accepted.";
        try { msg = (await r.json()).error || msg; } catch (e) { /* not JSON */ }
        if (r.status === 409) hide();
        $("error").textContent = msg;
      }
    } catch (e) {
      $("error").textContent = "Could not send the answer: connection lost.";
    } finally {
      sending = false;
    }
  }

  // ---- bounding box -------------------------------------------------------
  const clamp = (v) => Math.min(1, Math.max(0, v));
  function normalised(ev) {
    const c = $("bbox-canvas").getBoundingClientRect();
    return [clamp((ev.clientX - c.left) / c.width), clamp((ev.clientY - c.top) / c.height)];
  }
  function setBox(b) {
    if (!b) { box = null; } else {
      const [x0, y0, x1, y1] = b.map(clamp);
      box = [Math.min(x0, x1), Math.min(y0, y1), Math.max(x0, x1), Math.max(y0, y1)];
    }
    syncInputs();
    draw();
  }
  function syncInputs() {
    ["x0", "y0", "x1", "y1"].forEach((k, i) => {
      $("bbox-" + k).value = box ? Math.round(box[i] * 100) : "";
    });
    $("bbox-readout").textContent = box
      ? "Box: left " + Math.round(box[0] * 100) + "%, top " + Math.round(box[1] * 100) +
        "%, right " + Math.round(box[2] * 100) + "%, bottom " + Math.round(box[3] * 100) + "%."
      : "No box yet.";
  }
  function draw() {
    const cv = $("bbox-canvas");
    const g = cv.getContext("2d");
    const w = cv.width, h = cv.height;
    g.clearRect(0, 0, w, h);
    g.fillStyle = "#f4f1ea"; g.fillRect(0, 0, w, h);
    if (picture) {
      // Box coordinates are relative to the picture, stretched to the canvas.
      g.drawImage(picture, 0, 0, w, h);
    } else {
      // No picture: a plate, with the food named in the middle.
      g.fillStyle = "#ffffff"; g.strokeStyle = "#555555"; g.lineWidth = 3;
      g.beginPath(); g.ellipse(w / 2, h / 2, w * 0.42, h * 0.42, 0, 0, 2 * Math.PI); g.fill(); g.stroke();
    }
    if (current && !picture) {
      g.fillStyle = "#1a1a1a"; g.font = "bold 28px system-ui, sans-serif"; g.textAlign = "center";
      g.fillText(current.item.label, w / 2, h / 2 + 10);
    }
    if (box) {
      g.strokeStyle = "#000000"; g.lineWidth = 6;
      g.strokeRect(box[0] * w, box[1] * h, (box[2] - box[0]) * w, (box[3] - box[1]) * h);
      g.strokeStyle = "#ffd400"; g.lineWidth = 2;
      g.strokeRect(box[0] * w, box[1] * h, (box[2] - box[0]) * w, (box[3] - box[1]) * h);
    }
  }
  function setupBox() {
    const cv = $("bbox-canvas");
    cv.addEventListener("pointerdown", (ev) => {
      if (scanning()) return;
      cv.setPointerCapture(ev.pointerId);
      drag = normalised(ev);
      setBox([drag[0], drag[1], drag[0], drag[1]]);
    });
    cv.addEventListener("pointermove", (ev) => {
      if (!drag) return;
      const p = normalised(ev);
      setBox([drag[0], drag[1], p[0], p[1]]);
    });
    const end = () => { drag = null; };
    cv.addEventListener("pointerup", end);
    cv.addEventListener("pointercancel", end);
    cv.addEventListener("keydown", (ev) => {
      const step = 0.02;
      const moves = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step] };
      const m = moves[ev.key];
      if (!m) return;
      ev.preventDefault();
      let b = box || [0.4, 0.4, 0.6, 0.6];
      if (ev.shiftKey) {
        b = [b[0], b[1], Math.max(b[0] + 0.02, b[2] + m[0]), Math.max(b[1] + 0.02, b[3] + m[1])];
      } else {
        const dx = Math.min(Math.max(m[0], -b[0]), 1 - b[2]);
        const dy = Math.min(Math.max(m[1], -b[1]), 1 - b[3]);
        b = [b[0] + dx, b[1] + dy, b[2] + dx, b[3] + dy];
      }
      setBox(b);
    });
    const names = [["top left", "top", "top right"], ["left", "middle", "right"], ["bottom left", "bottom", "bottom right"]];
    const regions = $("regions");
    for (let r = 0; r < 3; r++) {
      for (let c = 0; c < 3; c++) {
        const b = document.createElement("button");
        b.type = "button";
        b.className = "region";
        b.id = "region-" + (r * 3 + c);
        b.textContent = names[r][c];
        b.setAttribute("aria-label", "Box around the " + names[r][c] + " of the plate");
        b.addEventListener("click", () => setBox([c / 3, r / 3, (c + 1) / 3, (r + 1) / 3]));
        regions.appendChild(b);
      }
    }
    ["x0", "y0", "x1", "y1"].forEach((k) => {
      $("bbox-" + k).addEventListener("change", () => {
        const v = ["x0", "y0", "x1", "y1"].map((n) => parseFloat($("bbox-" + n).value));
        if (v.every((x) => Number.isFinite(x))) setBox(v.map((x) => x / 100));
      });
    });
    $("send-box").addEventListener("click", () => {
      if (!box || box[2] - box[0] <= 0 || box[3] - box[1] <= 0) {
        $("error").textContent = "Draw a box first (or pick a region).";
        return;
      }
      send({ type: "bounding_box", bbox: { x0: box[0], y0: box[1], x1: box[2], y1: box[3] } });
    });
  }

  // ---- single-switch scanning (scan.js) ----------------------------------
  // The highlight steps through the open question's answer controls.
  function controls() {
    const sel = "#answer-area fieldset:not([hidden]) button, #answer-area fieldset:not([hidden]) textarea, #decline";
    return Array.from(document.querySelectorAll(sel)).filter((e) => !e.disabled && e.offsetParent !== null);
  }
  const scan = hilScan({ controls: controls, active: () => current !== null });
  const scanning = scan.scanning;

  document.addEventListener("DOMContentLoaded", () => {
    setupBox();
    $("decline").addEventListener("click", () => send({ type: "declined" }));
    $("send-text").addEventListener("click", () => {
      const text = $("answer-text").value.trim();
      if (!text) { $("error").textContent = "Type an answer first, or choose \"I don't know\"."; return; }
      send({ type: "text", text: text });
    });
    syncInputs();
    poll();
  });
})();
