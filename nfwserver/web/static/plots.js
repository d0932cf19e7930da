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
    for (const el of [0, 30, 60]) {
      svgEl("circle", { class: "grid", r: 90 - el, cx: 0, cy: 0 }, svg);
      const [x, y] = polarXY(135, el);  // on the south-east diagonal, clear of the N/E/S/W letters
      svgEl("text", { class: "gridtext ring", x: x + 1.5, y: y - 1.5, "data-testid": "ring-" + el }, svg).textContent = el + "\u00b0";
    }
    for (let az = 0; az < 360; az += 30) {
      const [x, y] = polarXY(az, 0);
      svgEl("line", { class: "grid", x1: 0, y1: 0, x2: x, y2: y }, svg);
    }
    this.letters = [];  // where N, E, S and W are written: labels keep clear of them too
    for (const [t, az] of [["N", 0], ["E", 90], ["S", 180], ["W", 270]]) {
      const [x, y] = polarXY(az, -11);
      svgEl("text", { class: "gridtext", x: x, y: y + 2.5, "text-anchor": "middle" }, svg).textContent = t;
      this.letters.push([x, y, 4.5]);
    }
    this.track = svgEl("polyline", { class: "track" }, svg);
    this.marks = svgEl("g", {}, svg);
    this.target = svgEl("rect", { class: "target hidden", width: 9, height: 9, "data-testid": "rotor-target" }, svg);
    this.actual = svgEl("path", { class: "actual hidden", d: "M0,-5 L5,0 L0,5 L-5,0 Z", "data-testid": "rotor-actual" }, svg);
    this.sat = svgEl("circle", { class: "sat hidden", r: 4.5, "data-testid": "sat-marker" }, svg);
    this.labels = svgEl("g", {}, svg);  // above every marker, each placed clear of the marks (placeLabels)
    this.points = [];
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
    this.labels.textContent = "";
    this.points = [];
    if (!track || !track.points) { this.track.setAttribute("points", ""); return; }
    this.track.setAttribute("points", track.always_up ? "" : track.points.filter(p => p[1] > -2)
      .map(([az, el]) => polarXY(az, el).map(v => v.toFixed(2)).join(",")).join(" "));
    const keys = track.always_up ? [["tca", "up all day"]] : [["aos", "AOS"], ["tca", "TCA"], ["los", "LOS"]];
    for (const [key, label] of keys) {
      const p = track[key];
      if (!p) continue;
      const [x, y] = polarXY(p.az, p.el);
      svgEl("circle", { class: "passmark", cx: x, cy: y, r: track.always_up ? 3.5 : 2.2, "data-testid": "pass-" + key }, this.marks);
      const text = svgEl("text", { class: "passlabel", "data-testid": "label-" + key }, this.labels);
      text.textContent = label;
      this.points.push({ x, y, text, width: label.length * 4.3 });
    }
    this.placeLabels();
  },
  // Each label goes where it covers no marker (pass marks, satellite, rotor marks) and no other label.
  placeLabels() {
    const circles = this.points.map(p => [p.x, p.y, 3]).concat(this.letters);
    for (const node of [this.sat, this.target, this.actual]) {
      if (node.classList.contains("hidden") || !node.hasAttribute("data-az")) continue;
      const [x, y] = polarXY(Number(node.getAttribute("data-az")), Number(node.getAttribute("data-el")));
      circles.push([x, y, 6]);
    }
    const placed = [];
    const clear = (x0, y0, w, h) => x0 >= -110 && x0 + w <= 110 && y0 >= -110 && y0 + h <= 110 &&
      circles.every(([cx, cy, r]) => cx + r < x0 || cx - r > x0 + w || cy + r < y0 || cy - r > y0 + h) &&
      placed.every(([a, b, c, d]) => a + c < x0 || a > x0 + w || b + d < y0 || b > y0 + h);
    for (const p of this.points) {
      const h = 7, w = p.width;
      const spots = [[4, -9], [4, 2], [-4 - w, -9], [-4 - w, 2], [-w / 2, -13], [-w / 2, 6], [8, -3.5], [-8 - w, -3.5],
        [12, -14], [-12 - w, 7], [12, 7], [-12 - w, -14]];
      let [dx, dy] = spots[0];
      for (const spot of spots) if (clear(p.x + spot[0], p.y + spot[1], w, h)) { [dx, dy] = spot; break; }
      placed.push([p.x + dx, p.y + dy, w, h]);
      p.text.setAttribute("x", (p.x + dx).toFixed(2));
      p.text.setAttribute("y", (p.y + dy + h - 1).toFixed(2));  // text y is its baseline
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
    if (this.points.length) this.placeLabels();
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
