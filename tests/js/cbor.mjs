// roslibjs, unchanged, subscribing with compression "cbor" to the cbrs rosbridge server: what
// tests/test_rosbridge_roslibjs_cbor.py asserts on. roslibjs decodes each binary frame with the npm
// cbor2 package, which reads RFC 8746 typed arrays into JavaScript typed arrays.
//
//     node tests/js/cbor.mjs PORT
//
// It subscribes (CBOR, and plain JSON on another connection) to the server's /test/scan and latched
// /test/latched, and to /chatter, then calls /test/go (the server publishes on /test/scan) and
// publishes on /chatter from a third connection. Prints one line of JSON: every message heard, each
// value described so JSON can carry it (a typed array as {"typed": its class, "values": [...]}, a
// BigInt as {"bigint": "digits"}). Every wait is bounded: a step without answer fails the script.

import { Ros, Service, Topic } from "roslib";
import { bounded as boundedFor } from "./bounded.mjs";

const WAIT = 5000;
const url = `ws://127.0.0.1:${Number(process.argv[2])}`;

setTimeout(() => {
  console.error("cbor.mjs: gave up after 30 s");
  process.exit(2);
}, 30000).unref();

const bounded = (what, executor) => boundedFor(what, WAIT, executor);

function connect() {
  return bounded("connect", (resolve, reject) => {
    const ros = new Ros({ url });
    ros.on("connection", () => resolve(ros));
    ros.on("error", (error) => reject(new Error(`connect: ${error?.message ?? error}`)));
  });
}

// A decoded value as JSON can carry it, saying which values were typed arrays, byte strings or BigInts.
function describe(value) {
  if (typeof value === "bigint") return { bigint: value.toString() };
  if (ArrayBuffer.isView(value)) return { typed: value.constructor.name, values: Array.from(value, describe) };
  if (Array.isArray(value)) return value.map(describe);
  if (value !== null && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([key, item]) => [key, describe(item)]));
  }
  return value;
}

function call(ros, name, request = {}) {
  const service = new Service({ ros, name, serviceType: "any" });
  return bounded(`call ${name}`, (resolve, reject) => service.callService(request, resolve, reject));
}

const [cbor, plain, talker] = [await connect(), await connect(), await connect()];
const heard = { scan: [], scan_json: [], latched: [], chatter: [] };
const listen = (ros, name, messageType, compression, into) =>
  new Topic({ ros, name, messageType, compression }).subscribe((message) => into.push(describe(message)));
listen(cbor, "/test/scan", "sensor_msgs/LaserScan", "cbor", heard.scan);
listen(plain, "/test/scan", "sensor_msgs/LaserScan", "none", heard.scan_json);
listen(cbor, "/test/latched", "nav_msgs/OccupancyGrid", "cbor", heard.latched);
listen(cbor, "/chatter", "std_msgs/String", "cbor", heard.chatter);
await call(plain, "/rosapi/get_time"); // both connections' subscriptions are in place once they answer
await call(cbor, "/test/go");

const chatter = new Topic({ ros: talker, name: "/chatter", messageType: "std_msgs/String" });
chatter.publish({ data: "snow ☃", n: 1, x: 1.5, list: [1, 2.5, "a", null, [true]], nested: { deep: { k: -3 } } });

const full = () => heard.scan.length && heard.scan_json.length && heard.latched.length && heard.chatter.length;
const deadline = Date.now() + WAIT;
while (!full() && Date.now() < deadline) {
  await new Promise((resolve) => setTimeout(resolve, 20));
}
await new Promise((resolve) => setTimeout(resolve, 200)); // anything heard twice would show now
console.log(JSON.stringify(heard));
process.exit(0);
