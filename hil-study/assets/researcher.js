// The researcher's page: enrol participants and follow their progress
// (refreshed every 2 s). A file of its own: the pages' security policy
// runs no inline script.
(function () {
  const $ = (id) => document.getElementById(id);
  const base = location.origin;
  function cell(tr, text) { const td = document.createElement("td"); td.textContent = text; tr.appendChild(td); return td; }
  async function refresh() {
    try {
      const r = await fetch("api/progress", { cache: "no-store" });
      const v = await r.json();
      const body = $("rows");
      body.textContent = "";
      v.participants.forEach((p) => {
        const tr = document.createElement("tr");
        cell(tr, p.participant); cell(tr, p.population);
        cell(tr, p.conditions_done + " / " + p.conditions); cell(tr, String(p.surveys)); cell(tr, p.phase);
        cell(tr, p.seen_s_ago === null ? "never" : Math.round(p.seen_s_ago) + " s ago");
        const td = cell(tr, ""); const a = document.createElement("a"); a.href = base + p.link; a.textContent = base + p.link; td.appendChild(a);
        body.appendChild(tr);
      });
    } catch (e) { /* the server may be restarting: try again */ }
  }
  $("enrol").addEventListener("click", async () => {
    const r = await fetch("api/participants", { method: "POST", headers: { "Content-Type": "application/json" },
      body: JSON.stringify({ population: $("population").value }) });
    const v = await r.json();
    $("enrolled").textContent = r.ok ? ("Enrolled " + v.participant + ": " + base + v.link) : ("Not enrolled: " + v.error);
    refresh();
  });
  refresh();
  setInterval(refresh, 2000);
})();
