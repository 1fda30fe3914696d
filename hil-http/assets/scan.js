// Single-switch scanning, shared by the robot's query page and the study
// pages. When the page's "Switch scanning" box (#scan-toggle) is ticked, a
// highlight steps through the controls the page names, one every
// #scan-speed milliseconds; one switch (Space, Enter, or a tap anywhere
// but on the scanning settings) activates the highlighted control. While
// scanning, a tap never clicks what is under the finger.
//
// hilScan({ controls, active }) sets it up on DOMContentLoaded and returns
// { scanning, restart, stop }: `controls()` lists the controls to step
// through, in order; `active()` says whether there is anything to scan now
// (default: always). Plain JavaScript, nothing loaded from elsewhere.
"use strict";
window.hilScan = function (opts) {
  const $ = (id) => document.getElementById(id);
  const active = opts.active || (() => true);
  let timer = null;
  let index = -1;
  let programmatic = false;  // a click made by the switch, not by a tap
  const scanning = () => $("scan-toggle").checked;
  const isRadio = (el) => el.tagName === "INPUT" && el.type === "radio";
  // Typing needs a keyboard: the switch hands such a control the focus.
  const isText = (el) => el.tagName === "TEXTAREA" || (el.tagName === "INPUT" && el.type === "text");
  const onSettings = (ev) => ev.target === $("scan-toggle") || ev.target === $("scan-speed") ||
    !!(ev.target.closest && ev.target.closest("label.scan-toggle, label.scan-speed"));

  function unmark() {
    document.querySelectorAll(".scan-focus").forEach((e) => e.classList.remove("scan-focus"));
  }
  function stop() {
    if (timer) clearInterval(timer);
    timer = null;
    unmark();
  }
  function restart() {
    stop();
    if (!scanning() || !active()) return;
    index = -1;
    const tick = () => {
      const list = opts.controls();
      if (!list.length) return;
      unmark();
      index = (index + 1) % list.length;
      const el = list[index];
      // A radio button is small: its label carries the highlight.
      (isRadio(el) ? el.parentElement : el).classList.add("scan-focus");
      el.focus();
    };
    tick();
    timer = setInterval(tick, parseInt($("scan-speed").value, 10));
  }
  function switchPressed(ev) {
    if (!scanning() || !active() || onSettings(ev)) return;
    const el = document.activeElement;
    if (!el || !document.querySelector(".scan-focus")) return;
    if (isText(el)) { stop(); el.focus(); return; }
    ev.preventDefault();
    programmatic = true;
    el.click();
    programmatic = false;
    // Choosing a radio answer leaves the highlight where it is, so that the
    // next press can move on to sending.
    if (!isRadio(el)) restart();
  }

  document.addEventListener("DOMContentLoaded", () => {
    $("scan-toggle").addEventListener("change", restart);
    $("scan-speed").addEventListener("change", restart);
    document.addEventListener("keydown", (ev) => {
      if (scanning() && (ev.key === " " || ev.key === "Enter")) switchPressed(ev);
    }, true);
    document.addEventListener("pointerdown", (ev) => { if (scanning()) switchPressed(ev); }, true);
    document.addEventListener("click", (ev) => {
      if (scanning() && !programmatic && !onSettings(ev)) {
        ev.preventDefault();
        ev.stopPropagation();
      }
    }, true);
  });
  return { scanning, restart, stop };
};
