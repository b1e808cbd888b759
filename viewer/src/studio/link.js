// The studio's one WebSocket to the kernel (docs/studio.md): JSON commands, each answered by one
// JSON reply and the binary net frames that follow it. A drag keeps at most one update in flight
// and replaces a waiting one by the newest (the kernel does the same with what queues there), so
// the picture follows the pointer without a backlog however slow a step is.

/**
 * Decodes a binary frame: {header, points, weights} (Float64Arrays) for a net or a curve;
 * {header, positions, normals, uv, triangles, nodeFace} for a model's mesh; {header, faces} for a
 * model's nets (each face {degrees, counts, knots_u, knots_v, rational, reversed, points,
 * weights}), sent instead of its mesh while the mesh's topology holds; {header, values} for a
 * surface's deviation map.
 */
export function decodeFrame(buffer) {
  const view = new DataView(buffer);
  const length = view.getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, length)));
  const start = Math.ceil((4 + length) / 8) * 8;
  if (header.kind === 'mesh') {
    // a model's trimmed mesh: positions, normals, (u, v) (float64), then uint32 triangles and faces
    const n = header.vertices;
    const m = header.triangles;
    const expected = start + 68 * n + 12 * m;
    if (buffer.byteLength !== expected) throw new Error(`frame "${header.name}": ${buffer.byteLength} bytes, expected ${expected}`);
    return {
      header,
      positions: new Float64Array(buffer, start, 3 * n),
      normals: new Float64Array(buffer, start + 24 * n, 3 * n),
      uv: new Float64Array(buffer, start + 48 * n, 2 * n),
      triangles: new Uint32Array(buffer, start + 64 * n, 3 * m),
      nodeFace: new Uint32Array(buffer, start + 64 * n + 12 * m, n),
    };
  }
  if (header.kind === 'model_nets') {
    let at = start;
    const faces = header.faces.map((f) => {
      const count = f.counts[0] * f.counts[1];
      const face = { ...f, points: new Float64Array(buffer, at, 3 * count), weights: new Float64Array(buffer, at + 24 * count, count) };
      at += 32 * count;
      return face;
    });
    if (buffer.byteLength !== at) throw new Error(`frame "${header.name}": ${buffer.byteLength} bytes, expected ${at}`);
    return { header, faces };
  }
  if (header.kind === 'deviation') {
    // a surface's deviation from its last step's pointwise deformation: rows x cols float64
    const expected = start + 8 * header.rows * header.cols;
    if (buffer.byteLength !== expected) throw new Error(`frame "${header.name}": ${buffer.byteLength} bytes, expected ${expected}`);
    return { header, values: new Float64Array(buffer, start, header.rows * header.cols) };
  }
  const count = header.kind === 'curve' ? header.knots.length - header.degree - 1 : header.counts[0] * header.counts[1];
  const expected = start + 32 * count;
  if (buffer.byteLength !== expected) throw new Error(`frame "${header.name}": ${buffer.byteLength} bytes, expected ${expected}`);
  // Float64Array needs 8-byte alignment: the frame pads its header to a multiple of 8
  const points = new Float64Array(buffer, start, 3 * count);
  const weights = new Float64Array(buffer, start + 24 * count, count);
  return { header, points, weights };
}

export class Link {
  /** `onReply(reply, frames, meta)` gets every reply; meta = {command, sentAt, inputAt}. */
  constructor(url, onReply, onClose) {
    this.onReply = onReply;
    this.onClose = onClose;
    this.inFlight = null; // {command, sentAt, inputAt, resolve, frames, reply, waiting}
    this.queue = []; // commands waiting for the one in flight
    this.pendingDrag = null; // the newest drag update not yet sent
    this.socket = new WebSocket(url);
    this.socket.binaryType = 'arraybuffer';
    this.opened = new Promise((resolve, reject) => {
      this.socket.onopen = () => resolve();
      this.socket.onerror = () => reject(new Error(`cannot open the studio's socket ${url}`));
    });
    this.socket.onclose = (event) => this.onClose && this.onClose(event);
    this.socket.onmessage = (event) => this.receive(event.data);
  }

  get busy() {
    return this.inFlight !== null || this.queue.length > 0 || this.pendingDrag !== null;
  }

  /** Sends a command; resolves with {reply, frames} once its reply and frames have arrived. */
  send(command, inputAt = performance.now()) {
    return new Promise((resolve) => {
      this.queue.push({ command, inputAt, resolve });
      this.pump();
    });
  }

  /**
   * A drag update (a command, or a function that builds it when it is sent): sent at once when nothing is in flight, else it waits, replacing any waiting
   * drag update (the newest wins). Resolves with the reply of the update finally sent, or null
   * when a newer one replaced it.
   */
  drag(command, inputAt = performance.now()) {
    return new Promise((resolve) => {
      if (this.pendingDrag) this.pendingDrag.resolve(null);
      this.pendingDrag = { command, inputAt, resolve };
      this.pump();
    });
  }

  /**
   * The command in flight, for the progress line: {op, sentAt, progress (the kernel's last
   * progress line for it, or null)}; null when nothing waits for an answer.
   */
  get running() {
    const f = this.inFlight;
    return f && { op: f.command.op, kind: f.command.kind, nets: f.command.nets, sentAt: f.sentAt, progress: f.progress || null };
  }

  /**
   * Cancels the command in flight (docs/studio.md § Long jobs): the kernel stops it at its next
   * check and answers it with an error of category "cancelled"; the message itself gets no reply.
   */
  cancel() {
    if (this.inFlight) this.socket.send(JSON.stringify({ op: 'cancel' }));
  }

  /** Drops the waiting drag update, if any (resolved with null). */
  cancelDrag() {
    if (this.pendingDrag) this.pendingDrag.resolve(null);
    this.pendingDrag = null;
  }

  pump() {
    if (this.inFlight) return;
    let next = this.queue.shift();
    if (!next && this.pendingDrag) {
      next = this.pendingDrag;
      this.pendingDrag = null;
    }
    if (!next) return;
    // a drag update may be built when it is sent, from the document as the last reply left it
    const command = typeof next.command === 'function' ? next.command() : next.command;
    if (!command) {
      next.resolve(null);
      this.pump();
      return;
    }
    this.inFlight = { ...next, command, sentAt: performance.now(), reply: null, frames: [], waiting: 0 };
    this.socket.send(JSON.stringify(command));
  }

  receive(data) {
    const f = this.inFlight;
    if (!f) return; // nothing asked: ignore
    if (typeof data === 'string') {
      const text = JSON.parse(data);
      if (text.op === 'progress') {
        // what a command running over half a second is doing: not its reply
        f.progress = text;
        return;
      }
      f.reply = text;
      f.waiting = ['surfaces', 'curves', 'befores', 'deviations', 'models'].reduce((n, k) => n + (f.reply[k] ? f.reply[k].length : 0), 0);
      if (f.reply.op === 'error') f.waiting = 0;
    } else {
      f.frames.push(decodeFrame(data));
      f.waiting--;
    }
    if (f.reply && f.waiting <= 0) {
      this.inFlight = null;
      const result = { reply: f.reply, frames: f.frames };
      this.onReply(f.reply, f.frames, { command: f.command, sentAt: f.sentAt, inputAt: f.inputAt });
      f.resolve(result);
      this.pump();
    }
  }
}
