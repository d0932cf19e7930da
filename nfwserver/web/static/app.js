// The dashboard: follows /api/stream (Server-Sent Events), fills the page with textContent only
// (names and strings from clients are never parsed as HTML), sends controls to /api/command.
"use strict";
const $ = id => document.getElementById(id);
const T = id => document.querySelector(`[data-testid="${id}"]`);
const MAX_LOG_ROWS = 500;
let frame = null, passesVersion = -1, passes = null, control = false;

function text(id, value) { const el = T(id); if (el) el.textContent = value; return el; }
function fixed(v, n) { return v === null || v === undefined ? "-" : Number(v).toFixed(n); }
function hhmmss(iso) { return iso ? iso.slice(11, 19) : "-"; }
// The browser's local time, or "" where its zone is UTC there (the UTC time is shown already).
function local(iso) {
  if (!iso) return "";
  const when = new Date(iso);
  return when.getTimezoneOffset() === 0 ? "" : when.toLocaleTimeString([], { hour: "2-digit", minute: "2-digit", second: "2-digit" });
}
function latLon(lat, lon) {
  return `${Math.abs(lat).toFixed(2)}\u00b0${lat < 0 ? "S" : "N"} ${Math.abs(lon).toFixed(2)}\u00b0${lon < 0 ? "W" : "E"}`;
}
function duration(s) {
  if (s === null || s === undefined) return "-";
  s = Math.max(0, Math.round(s));
  const h = Math.floor(s / 3600), m = Math.floor(s / 60) % 60, r = s % 60;
  return (h ? h + ":" + String(m).padStart(2, "0") : m) + ":" + String(r).padStart(2, "0");
}
function badge(id, label, on, cls) {
  const el = text(id, label);
  el.className = "badge " + (cls || (on ? "on" : ""));
}
function row(cells, parent) {
  const tr = document.createElement("tr");
  for (const c of cells) {
    const td = document.createElement("td");
    if (Array.isArray(c)) { td.textContent = c[0]; const s = document.createElement("small"); s.textContent = c[1]; td.appendChild(s); }
    else td.textContent = c;
    tr.appendChild(td);
  }
  parent.appendChild(tr);
  return tr;
}

function renderNow(f) {
  const n = f.now, sat = n.satellite, pos = n.position;
  text("clock", hhmmss(n.time) + "Z");
  text("sat-name", sat ? sat.dde_name : "no satellite selected");
  text("sat-number", sat ? "(" + sat.catalog_number + ")" : "");
  text("sat-full", sat && sat.name !== sat.dde_name ? sat.name : "");
  badge("tune-state", "TUNE " + (n.tune ? "ON" : "OFF"), n.tune);
  badge("track-state", "TRACK " + (n.track ? "ON" : "OFF"), n.track);
  // Doppler tuning switched on does nothing for a satellite without a radio channel: say so, not a green ON.
  const idle = n.radio_tuning && !n.doppler;
  badge("radio-state", "DOPPLER " + (idle ? "IDLE: NO CHANNEL" : n.radio_tuning ? "ON" : "OFF"), n.radio_tuning,
        idle ? "warn" : undefined);
  badge("ah", "AH " + (pos ? (pos.above_horizon ? "Y" : "N") : "-"), pos && pos.above_horizon);
  text("az", pos ? fixed(pos.az, 1) : "-");
  text("el", pos ? fixed(pos.el, 1) : "-");
  text("range", pos ? fixed(pos.range_km, 1) : "-");
  text("rr", pos ? fixed(pos.range_rate_km_s, 4) : "-");
  const sp = n.subpoint;
  text("subpoint", sp ? `${latLon(sp.lat, sp.lon)} ${sp.locator}` : "-");
  text("nova-string", n.nova || "(nothing published: TUNE OFF or no position)");
  const ev = f.next_event, up = passes && passes.track && passes.track.always_up;
  text("countdown-label", up ? "Up" : ev ? ev.kind + " in" : "AOS in");
  text("countdown", up ? "all day" : ev ? duration(ev.seconds) : "-");
  const d = n.doppler;
  text("doppler", d ? `${d.channel}: RX ${(d.rx_hz / 1e6).toFixed(6)} MHz` + (d.tx_hz ? `  TX ${(d.tx_hz / 1e6).toFixed(6)} MHz` : "")
    : "no radio channel for this satellite");
  text("status-word", n.status.hex);
  text("status-flags", n.status.flags.join(", ") || "ok");
  const age = text("element-age", sat ? `elements epoch ${sat.epoch}, ${sat.age_days.toFixed(1)} days old` + (sat.stale ? " - STALE, update them" : "") : "elements -");
  age.className = sat && sat.stale ? "stale" : "muted";
  const faults = T("faults");
  faults.textContent = "";
  for (const [name, why] of Object.entries(f.links.faults)) {
    const li = document.createElement("li"); li.textContent = name + ": " + why; faults.appendChild(li);
  }
}

function renderDevices(f) {
  const r = f.rotor;
  const rotor = text("rotor", r ? `rotor ${r.state}: commanded ${r.target ? fixed(r.target.az, 1) + "/" + fixed(r.target.el, 1) : "-"}` +
    `, actual ${r.actual ? fixed(r.actual.az, 1) + "/" + fixed(r.actual.el, 1) : "-"}, flip ${r.flip_mode}` +
    (r.flipped ? " (inverted)" : "") + (r.suspended ? ", SUSPENDED: " + r.suspended : "") : "rotor: none configured");
  rotor.className = r && r.state !== "ok" ? "stale" : "muted";
  const d = f.radio;
  const radio = text("radio", d ? `radio ${d.state}, Doppler tuning ${d.tuning ? "on" : "off"}` +
    (d.rx_hz ? `, RX ${(d.rx_hz / 1e6).toFixed(6)} MHz` : "") + (d.tx_hz ? `, TX ${(d.tx_hz / 1e6).toFixed(6)} MHz` : "") +
    (d.error ? ` (${d.error})` : "") : "radio: none configured");
  radio.className = d && d.state !== "ok" ? "stale" : "muted";
  text("counts", Object.entries(f.clients.counts).map(([k, v]) => k.replace(/_/g, " ") + " " + v).join(", "));
  const links = T("links");
  links.textContent = "";
  for (const [name, state] of Object.entries(f.links.states)) {
    const li = document.createElement("li"); li.textContent = name + ": " + state;
    if (state !== "ok") li.className = "bad";
    links.appendChild(li);
  }
  const body = $("clientrows");
  body.textContent = "";
  for (const c of f.clients.list.slice(0, 30))
    row([c.name, c.connected ? "connected" : "gone", [c.last_kind + " " + c.last_text, hhmmss(c.last_time) + (c.accepted === false ? " refused" : "")]], body);
  T("flip-state").classList.toggle("hidden", !((r && r.flipped) || (passes && passes.track && passes.track.flipped)));
}

function logLine(e) {
  const li = document.createElement("li");
  li.textContent = `${hhmmss(e.time)} ${e.dir.toUpperCase().padEnd(4)} ${e.kind} ${e.client ? "[" + e.client + "] " : ""}${e.text}` +
    (e.detail ? "  -- " + e.detail : "") + (e.accepted === false ? "  REFUSED" : "");
  li.className = e.dir + (e.accepted === false ? " refused" : "");
  li.dataset.dir = e.dir;
  li.dataset.kind = e.kind;
  li.dataset.seq = e.seq;
  return li;
}
function applyFilter(li) {
  const q = $("logfilter").value.toLowerCase(), dir = $("logdir").value;
  li.hidden = (dir && li.dataset.dir !== dir) || (q && !li.textContent.toLowerCase().includes(q))
    || (li.dataset.kind === "publish" && !$("logpublish").checked);  // one a tick: shown on request
}
let lastSeq = 0;  // the newest event shown: a line is never shown twice, whatever the stream repeats
function addLog(events) {
  const list = $("logrows");
  const atBottom = list.scrollTop + list.clientHeight >= list.scrollHeight - 4;
  for (const e of events) {
    if (e.seq <= lastSeq) continue;
    lastSeq = e.seq;
    const li = logLine(e); applyFilter(li); list.appendChild(li);
  }
  while (list.childElementCount > MAX_LOG_ROWS) list.firstElementChild.remove();
  if (atBottom) list.scrollTop = list.scrollHeight;
}

function renderPasses() {
  const body = $("passes");
  body.textContent = "";
  if (!passes) return;
  Polar.horizon(passes.horizon);
  Polar.pass(passes.track);
  WorldMap.groundTrack(passes.ground_track);
  const leftOut = T("left-out"), names = passes.left_out || [];
  leftOut.textContent = names.length ? "Left out, position cannot be computed now: " + names.slice(0, 5).join(", ")
    + (names.length > 5 ? ", ..." : "") : "";
  leftOut.classList.toggle("hidden", !names.length);
  const failed = T("passes-error");
  failed.textContent = passes.error || "";
  failed.classList.toggle("hidden", !passes.error);
  T("schedule-note").classList.toggle("hidden", !!passes.schedule);
  Timeline.render($("timeline"), passes.schedule || null);
  const selected = frame && frame.now.satellite ? frame.now.satellite.catalog_number : null;
  if (!passes.passes.length) { row(["none in the next 12 h", "", "", "", "", "", ""], body); return; }
  for (const p of passes.passes) {
    const tr = row([p.name, [hhmmss(p.aos), local(p.aos)], [hhmmss(p.tca), local(p.tca)], [hhmmss(p.los), local(p.los)],
      p.max_el.toFixed(0) + "\u00b0", p.aos === null && p.los === null ? "up for the whole window" : duration(p.duration_s), p.flipped === null ? "-" : (p.flipped ? "yes" : "no")], body);
    tr.dataset.catalogNumber = p.catalog_number;
    if (p.catalog_number === selected) tr.classList.add("current");
    if (control) {
      tr.classList.add("selectable"); tr.tabIndex = 0; tr.title = "select " + p.name;
      tr.addEventListener("click", () => send("SAT=" + p.catalog_number));
      tr.addEventListener("keydown", e => { if (e.key === "Enter" || e.key === " ") { e.preventDefault(); send("SAT=" + p.catalog_number); } });
    }
  }
}
function loadPasses() {
  fetch("/api/passes").then(r => r.json()).then(p => { passes = p; renderPasses(); if (frame) renderNow(frame); })
    .catch(() => {});
}

function setControl(on) {
  if (on === control && document.body.dataset.ready) return;
  control = on;
  document.body.dataset.ready = "1";
  for (const b of T("controls").querySelectorAll("button, input")) b.disabled = !on;
  text("control-note", on ? "control is on: every command needs the token" : "control is off ([web] control)");
  renderPasses();
}

function send(command) {
  const reply = T("control-reply");
  const token = $("token").value;
  try { localStorage.setItem("nfw-token", token); } catch (e) { /* private mode */ }
  reply.textContent = command + " ...";
  reply.className = "reply";
  fetch("/api/command", { method: "POST", headers: { "Content-Type": "application/json" },
    body: JSON.stringify({ command: command, token: token }) })
    .then(r => r.json().then(body => ({ status: r.status, body: body })))
    .then(({ status, body }) => {
      reply.textContent = command + ": " + (body.ok ? body.message : "refused: " + body.message);
      reply.className = "reply " + (body.ok ? "ok" : "bad");
      reply.dataset.status = status;
    })
    .catch(err => { reply.textContent = command + ": " + err; reply.className = "reply bad"; });
}

function onFrame(f) {
  frame = f;
  renderNow(f);
  renderDevices(f);
  Polar.update(f);
  WorldMap.update(f);
  setControl(f.control);
  if (f.passes_version !== passesVersion) { passesVersion = f.passes_version; loadPasses(); }
  document.body.dataset.frames = String(Number(document.body.dataset.frames || 0) + 1);
}

function connect() {
  const link = T("connection");
  const source = new EventSource("/api/stream");
  source.addEventListener("history", e => { $("logrows").textContent = ""; lastSeq = 0; addLog(JSON.parse(e.data)); });
  source.addEventListener("state", e => {
    const f = JSON.parse(e.data);
    addLog(f.log || []);  // the lines this page was not sent yet, in every frame (a frame error's too)
    if (f.frame_error) {  // the station could not build a frame: say so, never "live" on an old one
      link.textContent = "not updating"; link.className = "badge bad"; link.title = f.frame_error;
      return;
    }
    link.textContent = "live"; link.className = "badge ok"; link.title = "";
    onFrame(f);
  });
  source.onerror = () => { link.textContent = "reconnecting"; link.className = "badge bad"; };
}

document.addEventListener("DOMContentLoaded", () => {
  Polar.init($("polar"));
  WorldMap.init($("map"));
  try { $("token").value = localStorage.getItem("nfw-token") || ""; } catch (e) { /* private mode */ }
  for (const b of T("controls").querySelectorAll("button[data-command]"))
    b.addEventListener("click", () => send(b.dataset.command));
  $("satform").addEventListener("submit", e => { e.preventDefault(); const v = $("satinput").value.trim(); if (v) send("SAT=" + v); });
  $("logfilter").addEventListener("input", () => { for (const li of $("logrows").children) applyFilter(li); });
  $("logdir").addEventListener("change", () => { for (const li of $("logrows").children) applyFilter(li); });
  $("logpublish").addEventListener("change", () => { for (const li of $("logrows").children) applyFilter(li); });
  if (new Date().getTimezoneOffset() === 0) text("passes-zone", "UTC");
  fetch("/api/help").then(r => r.json()).then(h => {
    for (const c of h.commands) { const li = document.createElement("li"); li.textContent = c.usage + " - " + c.summary; T("help").appendChild(li); }
  }).catch(() => {});
  setControl(false);
  connect();
});
