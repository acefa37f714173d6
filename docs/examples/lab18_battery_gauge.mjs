// The robot's battery gauge (the eighteenth round, docs/components.md "Tried by a component developer"): a
// component in JavaScript, roslibjs under Node, that streams a topic. It publishes the battery's state on
// /lab18_battery_01/state twice a second (a dashboard subscribes to it) and answers ReadBatteryLevel
// (lab18_battery.ttl) with the last reading; the update token, one /cbrs/register, then the service
// advertised, and /cbrs/heartbeat three times a lease, as docs/components.md "Writing one (JavaScript)" says.
// Needs roslib beside it (npm install roslib):
//   CBRS_UPDATE_TOKEN=secret node lab18_battery_gauge.mjs [ws://127.0.0.1:9090] [--answer ok|twice|untyped|hang]
//       [--rate HZ] [--again] [--seconds N]
// --answer twice sends each answer twice; untyped answers the level without its @type; hang never answers.
// --rate publishes that many readings a second (a flood, say 2000); --again registers a second time on the
// same connection once registered. It prints one line of JSON once registered and one per call; it exits 0
// after --seconds (120 by default), 1 with the reason when the server refuses or ends it.

import { readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { Ros, Service, Topic } from "roslib";

const args = process.argv.slice(2);
const option = (name, fallback) => (args.includes(name) ? args[args.indexOf(name) + 1] : fallback);
const url = args[0] && !args[0].startsWith("--") ? args[0] : "ws://127.0.0.1:9090";
const answer = option("--answer", "ok");
const rate = Number(option("--rate", "2"));
const LEASE = 3;
const here = dirname(fileURLToPath(import.meta.url));
const description = readFileSync(join(here, "lab18_battery.ttl"), "utf-8");
setTimeout(() => process.exit(0), Number(option("--seconds", "120")) * 1000).unref();

const stop = (reason) => {
  console.error(`battery gauge: stopped: ${reason}`);
  process.exit(1);
};
const ros = await new Promise((resolve, reject) => {
  const connection = new Ros({ url });
  connection.on("connection", () => resolve(connection));
  connection.on("error", (error) => reject(new Error(`cannot reach ${url}: ${error?.message ?? error}`)));
});
ros.on("close", () => stop("the server closed the connection"));
ros.authenticate(process.env.CBRS_UPDATE_TOKEN ?? "", "", "", "", 0, "", 0);

const call = (name, request) =>
  new Promise((resolve, reject) => new Service({ ros, name, serviceType: "" }).callService(request, resolve, reject));
const register = () => call("/cbrs/register", { description, ttl: LEASE });

let registered;
try {
  registered = await register();
} catch (error) {
  stop(`registration refused: ${error}`);
}

// the stream: a slowly draining battery
let percent = 87.0;
const state = new Topic({ ros, name: "/lab18_battery_01/state", messageType: "sensor_msgs/BatteryState" });
let published = 0;
const publish = () => {
  percent = Math.max(0, percent - 0.01);
  state.publish({ percentage: percent / 100, voltage: 12.1, power_supply_status: 2 });
  published += 1;
};
if (rate > 100) {
  // a flood: a batch every millisecond or so, as a stuck driver loop sends
  const batch = Math.ceil(rate / 1000);
  setInterval(() => { for (let i = 0; i < batch; i += 1) publish(); }, 1);
} else {
  setInterval(publish, 1000 / rate);
}

const service = new Service({ ros, name: "/lab18_battery_01/read", serviceType: "lab18_msgs/ReadBattery" });
service.advertiseAsync(async (request) => {
  console.log(JSON.stringify({ called: "/lab18_battery_01/read", request, published }));
  if (answer === "hang") return new Promise(() => {});
  const level = { "@type": "home:BatteryLevel", percent: Math.round(percent * 10) / 10 };
  if (answer === "untyped") return { batteryLevel: { percent: level.percent } };
  return { batteryLevel: level };
});
if (answer === "twice") {
  // a second answer of every call, sent as the raw protocol has it, after roslib's own
  ros.on("/lab18_battery_01/read", (message) => {
    if (message.op !== "call_service") return;
    setTimeout(() => ros.callOnConnection({
      op: "service_response", service: "/lab18_battery_01/read", id: message.id, result: true,
      values: { batteryLevel: { "@type": "home:BatteryLevel", percent: 1.0 } },
    }), 50);
  });
}
let again;
if (args.includes("--again")) {
  try {
    again = await register();
  } catch (error) {
    again = { refused: String(error) };
  }
}
console.log(JSON.stringify({ registered: registered.components, answer, rate, again }));

setInterval(() => {
  new Service({ ros, name: "/cbrs/heartbeat", serviceType: "cbrs/Heartbeat" }).callService({}, () => {}, (error) => {
    const reason = String(error);
    if (reason.includes("was deregistered") || reason.includes("advertise the service")) stop(reason);
    if (reason.includes("no live component")) stop(`the lease lapsed: ${reason}`);
  });
}, (LEASE * 1000) / 3);
