// The reading lamp's smart plug (the tenth round, docs/tasks.md "A tenth round"): a component program in
// JavaScript, roslibjs under Node, as docs/components.md "Writing one (JavaScript)" says: the update token
// (authenticate), one /cbrs/register of both components (lab10_lamp_switch.ttl), then the two services
// advertised, and /cbrs/heartbeat three times a lease on a schedule. Needs roslib beside it (npm install
// roslib) and docs/examples/lab10_reading_lamp.ttl in the ontology and the map of the server's store:
//   CBRS_UPDATE_TOKEN=secret cbrs --store S serve
//   CBRS_UPDATE_TOKEN=secret node lab10_lamp_switch.mjs [ws://127.0.0.1:9090] [--answer ok|text|hang] [--seconds N]
// It prints one line of JSON once registered and one per call. Its newcomer's mistakes, on purpose:
// --answer text answers the status as text ("on"), not a home:DeviceStatus; --answer hang never answers.
// It exits 0 after --seconds (120 by default), 1 with the reason when the server refuses or ends it.

import { readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { Ros, Service } from "roslib";

const args = process.argv.slice(2);
const option = (name, fallback) => (args.includes(name) ? args[args.indexOf(name) + 1] : fallback);
const url = args[0] && !args[0].startsWith("--") ? args[0] : "ws://127.0.0.1:9090";
const answer = option("--answer", "ok");
const LEASE = 3; // seconds; a beat every third of it
const here = dirname(fileURLToPath(import.meta.url));
const description = readFileSync(option("--description", join(here, "lab10_lamp_switch.ttl")), "utf-8");
setTimeout(() => process.exit(0), Number(option("--seconds", "120")) * 1000).unref();

const stop = (reason) => {
  console.error(`lamp plug: stopped: ${reason}`);
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

// 1. register first
let registered;
try {
  registered = await call("/cbrs/register", { description, ttl: LEASE });
} catch (error) {
  stop(`registration refused: ${error}`);
}

// 2. then provide the services
let on = false;
const provide = (topic, status) => {
  const service = new Service({ ros, name: topic, serviceType: "lab10_msgs/Switch" });
  service.advertiseAsync(async (request) => {
    console.log(JSON.stringify({ called: topic, request }));
    if (answer === "hang") return new Promise(() => {}); // never answers
    on = status === "home:SwitchedOn";
    if (answer === "text") return { lampStatus: on ? "on" : "off" };
    return { lampStatus: { "@type": status } };
  });
};
provide("/lab10_lamp_plug_01/switch_on", "home:SwitchedOn");
provide("/lab10_lamp_plug_01/switch_off", "home:SwitchedOff");
console.log(JSON.stringify({ registered: registered.components, answer }));

// 3. keep the lease
setInterval(() => {
  new Service({ ros, name: "/cbrs/heartbeat", serviceType: "cbrs/Heartbeat" }).callService({}, () => {}, (error) => {
    const reason = String(error);
    if (reason.includes("was deregistered") || reason.includes("advertise the service")) stop(reason);
    if (reason.includes("no live component")) stop(`the lease lapsed: ${reason}`);
  });
}, (LEASE * 1000) / 3);
