// A cbrs component written in JavaScript with roslibjs (npm "roslib"): a thermometer answering
// RoomTemperature. It does what the Python SDK (cbrs.component) does, over the rosbridge protocol:
// authenticate with the update token, provide its service, register its description with
// /cbrs/register, and renew its lease with /cbrs/heartbeat every second. docs/components.md.
//
//     node tests/js/thermometer.mjs PORT TOKEN DESCRIPTION.ttl [SECONDS]
//
// It prints one line of JSON once registered ({"registered": [...]}) and another per request it
// answers, and exits after SECONDS (60 by default) or when the server closes the connection.

import { readFileSync } from "node:fs";
import { Ros, Service } from "roslib";
import { bounded } from "./bounded.mjs";

const [port, token, descriptionFile, seconds = "60"] = process.argv.slice(2);
const WAIT = 10000;

setTimeout(() => process.exit(0), Number(seconds) * 1000).unref();

// bounded, with the failure named after what was waited for
const wait = (what, executor) =>
  bounded(what, WAIT, (resolve, reject) => executor(resolve, (error) => reject(new Error(`${what}: ${error}`))));

const ros = await wait("connect", (resolve, reject) => {
  const connection = new Ros({ url: `ws://127.0.0.1:${Number(port)}` });
  connection.on("connection", () => resolve(connection));
  connection.on("error", (error) => reject(error?.message ?? error));
});
ros.on("close", () => process.exit(0));
ros.authenticate(token, "", "", "", 0, "", 0); // cbrs takes its update token as the mac

const read = new Service({ ros, name: "/thermometer07/read", serviceType: "cbrs_msgs/RoomTemperature" });
await read.advertise((request, response) => {
  response.roomTemperature = { "@type": "home:RoomTemperature", celsius: 19.5, source: "roslibjs" };
  console.log(JSON.stringify({ answered: request }));
  return true;
});

const register = new Service({ ros, name: "/cbrs/register", serviceType: "cbrs/Register" });
const answer = await wait("register", (resolve, reject) =>
  register.callService({ description: readFileSync(descriptionFile, "utf-8"), ttl: 3 }, resolve, reject),
);
console.log(JSON.stringify({ registered: answer.components }));

const heartbeat = new Service({ ros, name: "/cbrs/heartbeat", serviceType: "cbrs/Heartbeat" });
setInterval(() => heartbeat.callService({}, () => {}, (error) => console.error(`heartbeat: ${error}`)), 1000);
