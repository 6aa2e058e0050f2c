// The package in Node.js (node --single-threaded-gc --test pkg/test.mjs, after web/build.sh):
// a recording simulated by the module itself is calibrated by `calibrate`, and the document
// is compared with the native command's on the same bytes (GMWM_BIN, default
// target/release/gmwm); a corrupt file gives gmwm's one line as a GmwmError.
import { test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdtempSync, writeFileSync, readFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { run, calibrate, calibrateAll, GmwmError } from "./index.js";

/** `gmwm simulate`'s CSV (column `x`) as a gyroscope axis, `gyro_x`. */
function asGyro(csv) {
  const text = new TextDecoder().decode(csv);
  assert.ok(text.startsWith("x\n"));
  return new TextEncoder().encode("gyro_x" + text.slice(1));
}

const GMWM = process.env.GMWM_BIN ?? new URL("../target/release/gmwm", import.meta.url).pathname;

test("a simulated recording calibrates as the native command does", async () => {
  const sim = await run(["simulate", "--model", "WN(sigma2=1e-4)+RW(gamma2=1e-9)", "--n", "65536",
    "--freq", "100", "--seed", "7", "-o", "sim.csv", "--quiet"]);
  assert.equal(sim.code, 0, sim.stderr);
  const csv = asGyro(sim.files.get("sim.csv"));
  assert.ok(csv.length > 100_000);
  const doc = await calibrate(csv, { name: "sim.csv", freq: 100, gyroUnit: "rad/s" });
  const dir = mkdtempSync(join(tmpdir(), "gmwm-pkg-"));
  writeFileSync(join(dir, "sim.csv"), csv);
  execFileSync(GMWM, ["calibrate", join(dir, "sim.csv"), "--freq", "100", "--gyro-unit", "rad/s",
    "--json", join(dir, "native.json"), "--quiet"], { stdio: ["ignore", "ignore", "inherit"] });
  const native = JSON.parse(readFileSync(join(dir, "native.json"), "utf8"));
  assert.equal(doc.axes.length, native.axes.length);
  for (const [a, b] of doc.axes.map((x, i) => [x, native.axes[i]])) {
    assert.equal(a.identified_model, b.identified_model);
    for (const key of ["noise_density", "bias_instability", "random_walk"]) {
      const [x, y] = [a[key].value, b[key].value];
      if (y === null) assert.equal(x, null);
      else assert.ok(Math.abs(x - y) <= 1e-9 * Math.abs(y), `${a.column} ${key}: ${x} vs ${y}`);
    }
  }
});

test("progress is reported and the filter files come back", async () => {
  const series = async (seed) => {
    const sim = await run(["simulate", "--model", "WN(sigma2=1e-4)+RW(gamma2=1e-9)", "--n", "16384",
      "--freq", "200", "--seed", String(seed), "-o", "s.csv", "--quiet"]);
    assert.equal(sim.code, 0, sim.stderr);
    return new TextDecoder().decode(sim.files.get("s.csv")).trim().split("\n").slice(1);
  };
  const [g, a] = [await series(1), await series(2)];
  const csv = ["gyro_x,accel_x", ...g.map((v, i) => `${v},${a[i]}`)].join("\n") + "\n";
  const seen = [];
  const all = await calibrateAll(csv, {
    name: "s.csv", freq: 200, gyroUnit: "rad/s", accelUnit: "m/s^2", exports: ["kalibr", "openvins"],
    onProgress: (p) => seen.push(p),
  });
  assert.ok(seen.length > 0 && seen.at(-1).total > 0, "no progress reported");
  assert.match(all.exports.kalibr, /gyroscope_noise_density/);
  assert.match(all.exports.openvins, /accelerometer_random_walk/);
  assert.ok(all.memoryBytes > 0 && all.seconds > 0);
});

test("a corrupt file is one line of gmwm's", async () => {
  const bytes = new Uint8Array([0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3, 1, 2, 3, 4, 5, 6, 7, 8, 9]);
  await assert.rejects(calibrate(bytes, { name: "broken.csv.gz" }), (e) => {
    assert.ok(e instanceof GmwmError);
    assert.match(e.message, /^broken\.csv\.gz: /);
    assert.equal(e.message.split("\n").length, 1);
    return true;
  });
});

test("ROS recordings are read from bytes (ROS1 bag and MCAP, the fuzz seeds)", async () => {
  for (const [seed, name] of [["ros1_bag/two_topics_extra", "r.bag"], ["mcap/temperature", "m.mcap"]]) {
    const bytes = readFileSync(new URL(`../fuzz/corpus/${seed}`, import.meta.url));
    const got = await run(["topics", name], { files: { [name]: bytes } });
    assert.equal(got.code, 0, got.stderr);
    const dir = mkdtempSync(join(tmpdir(), "gmwm-pkg-"));
    writeFileSync(join(dir, name), bytes);
    const native = execFileSync(GMWM, ["topics", name], { cwd: dir, encoding: "utf8" });
    assert.equal(got.stdout, native);
  }
});
