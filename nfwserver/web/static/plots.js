// The polar plot and the world map, drawn as SVG from the frame and /api/passes.
// Azimuth clockwise from north, elevation 90 at the centre; map: equirectangular, x = lon + 180, y = 90 - lat.
"use strict";
const SVGNS = "http://www.w3.org/2000/svg";

function svgEl(name, attrs, parent) {
  const el = document.createElementNS(SVGNS, name);
  for (const [k, v] of Object.entries(attrs || {})) el.setAttribute(k, v);
  if (parent) parent.appendChild(el);
  return el;
}

function polarXY(az, el) {
  const r = 90 - Math.max(-5, Math.min(90, el));
  const a = az * Math.PI / 180;
  return [r * Math.sin(a), -r * Math.cos(a)];
}

const Polar = {
  init(svg) {
    this.svg = svg;
    svg.textContent = "";
    this.mask = svgEl("path", { class: "mask" }, svg);
    for (const el of [0, 30, 60]) svgEl("circle", { class: "grid", r: 90 - el, cx: 0, cy: 0 }, svg);
    for (let az = 0; az < 360; az += 30) {
      const [x, y] = polarXY(az, 0);
      svgEl("line", { class: "grid", x1: 0, y1: 0, x2: x, y2: y }, svg);
    }
    for (const [t, az] of [["N", 0], ["E", 90], ["S", 180], ["W", 270]]) {
      const [x, y] = polarXY(az, -11);
      svgEl("text", { class: "gridtext", x: x, y: y + 2.5, "text-anchor": "middle" }, svg).textContent = t;
    }
    this.track = svgEl("polyline", { class: "track" }, svg);
    this.marks = svgEl("g", {}, svg);
    this.target = svgEl("rect", { class: "target hidden", width: 9, height: 9, "data-testid": "rotor-target" }, svg);
    this.actual = svgEl("path", { class: "actual hidden", d: "M0,-5 L5,0 L0,5 L-5,0 Z", "data-testid": "rotor-actual" }, svg);
    this.sat = svgEl("circle", { class: "sat hidden", r: 4.5, "data-testid": "sat-marker" }, svg);
  },
  horizon(points) {
    if (!points || !points.length) { this.mask.setAttribute("d", ""); return; }
    let d = "";
    points.forEach(([az, el], i) => { const [x, y] = polarXY(az, el); d += (i ? "L" : "M") + x.toFixed(2) + "," + y.toFixed(2); });
    d += "Z M0,-90 A90,90 0 1,0 0,90 A90,90 0 1,0 0,-90 Z";
    this.mask.setAttribute("d", d);
  },
  pass(track) {
    this.marks.textContent = "";
    if (!track || !track.points) { this.track.setAttribute("points", ""); return; }
    this.track.setAttribute("points", track.points.filter(p => p[1] > -2)
      .map(([az, el]) => polarXY(az, el).map(v => v.toFixed(2)).join(",")).join(" "));
    for (const key of ["aos", "tca", "los"]) {
      const p = track[key];
      if (!p) continue;
      const [x, y] = polarXY(p.az, p.el);
      svgEl("circle", { class: "passmark", cx: x, cy: y, r: 2.2, "data-testid": "pass-" + key }, this.marks);
      svgEl("text", { class: "passlabel", x: x + 3, y: y - 3 }, this.marks).textContent = key.toUpperCase();
    }
  },
  place(node, pos, fn) {
    if (!pos || pos.az === null || pos.el === null) { node.classList.add("hidden"); return; }
    node.classList.remove("hidden");
    const [x, y] = polarXY(pos.az, pos.el);
    fn(x, y);
    node.setAttribute("data-az", pos.az);
    node.setAttribute("data-el", pos.el);
  },
  update(frame) {
    const pos = frame.now.position;
    this.place(this.sat, pos, (x, y) => { this.sat.setAttribute("cx", x.toFixed(2)); this.sat.setAttribute("cy", y.toFixed(2)); });
    if (pos) this.sat.setAttribute("class", pos.el >= 0 ? "sat" : "sat below");
    const rotor = frame.rotor || {};
    this.place(this.target, rotor.target, (x, y) => { this.target.setAttribute("x", (x - 4.5).toFixed(2)); this.target.setAttribute("y", (y - 4.5).toFixed(2)); });
    this.place(this.actual, rotor.actual, (x, y) => this.actual.setAttribute("transform", `translate(${x.toFixed(2)},${y.toFixed(2)})`));
  },
};

function splitLon(points) {
  // [[lon, lat], ...] -> runs without antimeridian jumps
  const runs = [];
  let run = [];
  points.forEach(([lon, lat], i) => {
    if (i && Math.abs(lon - points[i - 1][0]) > 180) { runs.push(run); run = []; }
    run.push([lon, lat]);
  });
  if (run.length) runs.push(run);
  return runs;
}

function mapPath(runs) {
  return runs.map(r => r.map(([lon, lat], i) => (i ? "L" : "M") + (lon + 180).toFixed(1) + "," + (90 - lat).toFixed(1)).join("")).join("");
}

function footprintRing(lat0, lon0, diameterKm) {
  const d = diameterKm / 2 / 6371, la = lat0 * Math.PI / 180, lo = lon0 * Math.PI / 180, out = [];
  for (let b = 0; b <= 360; b += 5) {
    const br = b * Math.PI / 180;
    const lat = Math.asin(Math.sin(la) * Math.cos(d) + Math.cos(la) * Math.sin(d) * Math.cos(br));
    const lon = lo + Math.atan2(Math.sin(br) * Math.sin(d) * Math.cos(la), Math.cos(d) - Math.sin(la) * Math.sin(lat));
    out.push([((lon * 180 / Math.PI + 540) % 360) - 180, lat * 180 / Math.PI]);
  }
  return out;
}

const WorldMap = {
  init(svg) {
    this.svg = svg;
    svg.textContent = "";
    svgEl("rect", { class: "sea", x: 0, y: 0, width: 360, height: 180 }, svg);
    this.land = svgEl("path", { class: "land" }, svg);
    this.ground = svgEl("path", { class: "ground" }, svg);
    this.footprint = svgEl("path", { class: "footprint" }, svg);
    this.station = svgEl("circle", { class: "station hidden", r: 2, "data-testid": "map-station" }, svg);
    this.sat = svgEl("circle", { class: "sat hidden", r: 2.6, "data-testid": "map-sat" }, svg);
    fetch("/static/land.json").then(r => r.json()).then(data => {
      this.land.setAttribute("d", data.rings.map(flat => {
        let d = "";
        for (let i = 0; i < flat.length; i += 2) d += (i ? "L" : "M") + (flat[i] + 180) + "," + (90 - flat[i + 1]);
        return d + "Z";
      }).join(""));
    }).catch(() => {});
  },
  groundTrack(points) {
    this.ground.setAttribute("d", points && points.length ? mapPath(splitLon(points.map(([lat, lon]) => [lon, lat]))) : "");
  },
  update(frame) {
    const obs = frame.now.observer, sub = frame.now.subpoint;
    if (obs) {
      this.station.classList.remove("hidden");
      this.station.setAttribute("cx", ((obs.lon + 540) % 360).toFixed(2));
      this.station.setAttribute("cy", (90 - obs.lat).toFixed(2));
    }
    if (!sub) { this.sat.classList.add("hidden"); this.footprint.setAttribute("d", ""); return; }
    this.sat.classList.remove("hidden");
    this.sat.setAttribute("cx", (sub.lon + 180).toFixed(2));
    this.sat.setAttribute("cy", (90 - sub.lat).toFixed(2));
    this.footprint.setAttribute("d", mapPath(splitLon(footprintRing(sub.lat, sub.lon, sub.footprint_km))));
  },
};
