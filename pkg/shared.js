// What the threads of the threaded module share besides its memory: the control block through
// which `wasi.thread-spawn` hands a new thread to an idle worker, and the progress cell that
// any thread's progress line updates and the page reads (SharedArrayBuffers, so that neither
// needs the busy main thread's event loop).

/** Int32 words per worker slot: state (0 idle, 1 claimed, 2 running), thread id, start arg. */
export const SLOT = 4;
/** Words before the slots: the slot count and the last thread id given. */
const HEADER = 2;

/** A control block for `slots` workers. */
export function controlBlock(slots) {
  const ctl = new Int32Array(new SharedArrayBuffer(4 * (HEADER + slots * SLOT)));
  ctl[0] = slots;
  return ctl;
}

/** The index of slot `s`'s state word. */
export const slotState = (s) => HEADER + s * SLOT;

/**
 * `wasi.thread-spawn(start_arg)`: hands the thread to an idle worker and returns its id (> 0),
 * or -6 (EAGAIN) when every worker runs a thread (std's spawn then returns an error).
 */
export function threadSpawn(ctl, arg) {
  const slots = ctl[0];
  for (let s = 0; s < slots; s++) {
    const state = slotState(s);
    if (Atomics.compareExchange(ctl, state, 0, 1) === 0) {
      const tid = Atomics.add(ctl, 1, 1) + 1;
      Atomics.store(ctl, state + 1, tid);
      Atomics.store(ctl, state + 2, arg);
      Atomics.store(ctl, state, 2);
      Atomics.notify(ctl, state);
      return tid;
    }
  }
  return -6;
}

const PROGRESS = /^gmwm: progress: (.*): (\d+)\/(\d+) ?(.*)$/;
const TEXT_AT = 16;
const TEXT_MAX = 240;

/** A progress cell: [sequence, done, total, text length] and the text `message\tunit`. */
export function progressCell() {
  return new SharedArrayBuffer(TEXT_AT + TEXT_MAX);
}

/** Parses `gmwm: progress: MESSAGE: DONE/TOTAL UNIT`. */
export function parseProgress(line) {
  const m = PROGRESS.exec(line);
  return m ? { message: m[1], done: Number(m[2]), total: Number(m[3]), unit: m[4] } : null;
}

/** Writes a progress line into the cell; false if the line is not one. */
export function recordProgress(cell, line) {
  const p = parseProgress(line);
  if (!p) return false;
  if (!cell) return true;
  const words = new Int32Array(cell, 0, 4);
  const text = new TextEncoder().encode(`${p.message}\t${p.unit}`).slice(0, TEXT_MAX);
  new Uint8Array(cell, TEXT_AT, TEXT_MAX).set(text);
  Atomics.store(words, 1, p.done);
  Atomics.store(words, 2, p.total);
  Atomics.store(words, 3, text.length);
  Atomics.add(words, 0, 1);
  return true;
}

/**
 * Records in the cell that a thread trapped (a panic's abort): the program is over, but its
 * main thread may wait for that thread forever, so whoever reads the cell must stop it.
 */
export function recordTrap(cell, message) {
  if (!cell) return;
  const words = new Int32Array(cell, 0, 4);
  const text = new TextEncoder().encode(message).slice(0, TEXT_MAX);
  new Uint8Array(cell, TEXT_AT, TEXT_MAX).set(text);
  Atomics.store(words, 3, text.length);
  Atomics.store(words, 2, -1);
  Atomics.add(words, 0, 1);
}

/** The cell's last progress (`{message, done, total, unit}`), `{trap}` after a thread's trap,
 * or null before the first. */
export function readProgress(cell) {
  const words = new Int32Array(cell, 0, 4);
  if (Atomics.load(words, 0) === 0) return null;
  const len = Atomics.load(words, 3);
  const text = new TextDecoder().decode(new Uint8Array(cell, TEXT_AT, len).slice());
  if (Atomics.load(words, 2) === -1) return { trap: text };
  const [message, unit = ""] = text.split("\t");
  return { message, done: Atomics.load(words, 1), total: Atomics.load(words, 2), unit };
}
