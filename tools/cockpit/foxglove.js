// A Foxglove WebSocket protocol v1 client (subprotocol foxglove.websocket.v1), as much of it
// as the cockpit needs: subscribe to every advertised channel (JSON encoding), advertise the
// command topics and publish to them (clientPublish). docs/foxglove.md lists the channels.
const SUBPROTOCOL = "foxglove.websocket.v1";
const MESSAGE_DATA = 0x01;
const decoder = new TextDecoder();
const encoder = new TextEncoder();

export class FoxgloveClient {
  // handlers: onOpen(), onMessage(topic, msg, timeNs), onStatus(level, text, id), onClose()
  constructor(url, handlers) {
    this.handlers = handlers;
    this.channels = new Map(); // subscription id -> topic
    this.publishers = new Map(); // topic -> client channel id
    this.nextId = 1;
    this.ws = new WebSocket(url, [SUBPROTOCOL]);
    this.ws.binaryType = "arraybuffer";
    this.ws.onmessage = (e) => this.receive(e.data);
    this.ws.onclose = () => handlers.onClose?.();
    this.ws.onerror = () => {}; // onclose follows
  }

  get open() { return this.ws.readyState === WebSocket.OPEN; }

  receive(data) {
    if (typeof data === "string") {
      const m = JSON.parse(data);
      if (m.op === "serverInfo") this.handlers.onOpen?.(m);
      else if (m.op === "advertise") this.subscribe(m.channels);
      else if (m.op === "status") this.handlers.onStatus?.(m.level, m.message, m.id);
      return;
    }
    const view = new DataView(data);
    if (view.getUint8(0) !== MESSAGE_DATA) return;
    const topic = this.channels.get(view.getUint32(1, true));
    if (!topic) return;
    const timeNs = view.getBigUint64(5, true);
    this.handlers.onMessage?.(topic, JSON.parse(decoder.decode(new Uint8Array(data, 13))), timeNs);
  }

  subscribe(channels) {
    const subscriptions = [];
    for (const ch of channels) {
      if (ch.encoding !== "json") continue;
      const id = this.nextId++;
      this.channels.set(id, ch.topic);
      subscriptions.push({ id, channelId: ch.id });
    }
    if (subscriptions.length) this.ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
  }

  // Sends one command; false when the connection is not open (nothing was sent).
  publish(topic, obj) {
    if (!this.open) return false;
    let id = this.publishers.get(topic);
    if (id === undefined) {
      id = this.nextId++;
      this.publishers.set(topic, id);
      this.ws.send(JSON.stringify({ op: "advertise", channels: [{ id, topic, encoding: "json", schemaName: topic }] }));
    }
    const payload = encoder.encode(JSON.stringify(obj));
    const frame = new Uint8Array(5 + payload.length);
    frame[0] = MESSAGE_DATA;
    new DataView(frame.buffer).setUint32(1, id, true);
    frame.set(payload, 5);
    this.ws.send(frame);
    return true;
  }

  close() { this.ws.close(); }
}
