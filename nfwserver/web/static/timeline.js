// The autotrack schedule of the next hours as a timeline (the "schedule" of /api/passes): one lane per
// satellite in priority order, each candidate pass a bar from AOS to LOS; scheduled passes in their priority's
// colour, left-out passes grey with their reason on hover (title).  Names go in as textContent only.
"use strict";
const Timeline = (() => {
  const PALETTE = 6;  // priority colours, then again
  function ms(iso, fallback) { return iso ? Date.parse(iso) : fallback; }
  function hhmm(t) { return new Date(t).toISOString().slice(11, 16); }
  function render(box, schedule) {
    box.textContent = "";
    if (!schedule) return;
    const from = Date.parse(schedule.from), to = Date.parse(schedule.to), span = to - from;
    const lanes = new Map();
    for (const p of [...schedule.passes].sort((a, b) => a.priority - b.priority))
      if (!lanes.has(p.catalog_number)) lanes.set(p.catalog_number, p);
    const axis = document.createElement("div");
    axis.className = "tl-axis";
    for (let h = 0; h <= span / 3.6e6; h += 2) {
      const tick = document.createElement("span");
      tick.style.left = (h * 3.6e6 / span * 100).toFixed(3) + "%";
      tick.textContent = hhmm(from + h * 3.6e6);
      axis.appendChild(tick);
    }
    box.appendChild(axis);
    for (const [number, first] of lanes) {
      const lane = document.createElement("div");
      lane.className = "tl-lane";
      lane.dataset.catalogNumber = number;
      const name = document.createElement("span");
      name.className = "tl-name";
      name.textContent = first.name;
      lane.appendChild(name);
      const track = document.createElement("div");
      track.className = "tl-track";
      for (const p of schedule.passes) {
        if (p.catalog_number !== number) continue;
        const a = Math.max(from, ms(p.aos, from)), b = Math.min(to, ms(p.los, to));
        const bar = document.createElement("span");
        bar.className = "tl-bar " + (p.scheduled ? "scheduled prio-" + (p.priority % PALETTE) : "left-out");
        bar.style.left = ((a - from) / span * 100).toFixed(3) + "%";
        bar.style.width = Math.max(0.3, (b - a) / span * 100).toFixed(3) + "%";
        bar.dataset.aos = p.aos || "";
        bar.title = `${p.name} ${p.aos ? hhmm(ms(p.aos)) : "--:--"}-${p.los ? hhmm(ms(p.los)) : "--:--"} UTC, ` +
          `max ${p.max_el.toFixed(0)}\u00b0` + (p.scheduled ? ", scheduled" : ": left out, " + p.reason);
        track.appendChild(bar);
      }
      lane.appendChild(track);
      box.appendChild(lane);
    }
  }
  return { render };
})();
