// A cbrs component written in JavaScript with roslibjs (npm "roslib"): a thermometer answering
// RoomTemperature. It does what the Python SDK (cbrs.component) does, over the rosbridge protocol:
// authenticate with the update token, register its description with /cbrs/register, only then provide
// its service (so a refused copy takes no calls from the program already running), and renew its lease
// with /cbrs/heartbeat three times a lease (every second of the default 3 s), registering again when
// the server says the lease lapsed (the program was paused longer than its lease) and stopping when it
// was deregistered. docs/components.md.
//
//     node tests/js/thermometer.mjs PORT TOKEN DESCRIPTION.ttl [SECONDS] [LEASE]
//
// It prints one line of JSON once registered ({"registered": [...]}), one per request it answers
// ({"answered": ...}) and one each time it registers again ({"registeredAgain": [...]}). It exits 0
// after SECONDS (60 by default), and 1 with the reason on stderr when it cannot serve: its registration
// refused, the server gone, the component deregistered, or registering again refused 5 times.

import { readFileSync } from "node:fs";
import { Ros, Service } from "roslib";
import { bounded } from "./bounded.mjs";

const [port, token, descriptionFile, seconds = "60", lease = "3"] = process.argv.slice(2);
const WAIT = 10000;
const LEASE = Number(lease); // seconds; a heartbeat every third of it renews it
const TRIES = 5; // registrations tried after a lapse before giving up

setTimeout(() => process.exit(0), Number(seconds) * 1000).unref();

const stop = (reason) => {
  console.error(`thermometer: stopped serving: ${reason}`);
  process.exit(1); // for a supervisor to restart it
};

// bounded, with the failure named after what was waited for
const wait = (what, executor) =>
  bounded(what, WAIT, (resolve, reject) => executor(resolve, (error) => reject(new Error(`${what}: ${error}`))));

const ros = await wait("connect", (resolve, reject) => {
  const connection = new Ros({ url: `ws://127.0.0.1:${Number(port)}` });
  connection.on("connection", () => resolve(connection));
  connection.on("error", (error) => reject(error?.message ?? error));
});
ros.on("close", () => stop("the server closed the connection"));
ros.authenticate(token, "", "", "", 0, "", 0); // cbrs takes its update token as the mac

const description = readFileSync(descriptionFile, "utf-8");
const register = new Service({ ros, name: "/cbrs/register", serviceType: "cbrs/Register" });
const registered = () =>
  wait("register", (resolve, reject) => register.callService({ description, ttl: LEASE }, resolve, reject));

// 1. register first: a refusal (this program running twice, a wrong token) ends here, having provided nothing
let answer;
try {
  answer = await registered();
} catch (error) {
  stop(error.message);
}

// 2. then provide the service
const read = new Service({ ros, name: "/thermometer07/read", serviceType: "cbrs_msgs/RoomTemperature" });
await read.advertise((request, response) => {
  response.roomTemperature = { "@type": "home:RoomTemperature", celsius: 19.5, source: "roslibjs" };
  console.log(JSON.stringify({ answered: request }));
  return true;
});
console.log(JSON.stringify({ registered: answer.components }));

// 3. keep the lease: three beats a lease, not waiting for the last answer
const heartbeat = new Service({ ros, name: "/cbrs/heartbeat", serviceType: "cbrs/Heartbeat" });
let registration = 0; // beats answered for an older registration say nothing of this one
let tries = 0;
let registering = false;

async function registerAgain(why) {
  registering = true;
  try {
    const again = await registered();
    registration += 1;
    tries = 0;
    console.log(JSON.stringify({ registeredAgain: again.components }));
  } catch (error) {
    tries += 1;
    console.error(`thermometer: registering again failed (try ${tries} of ${TRIES}): ${error.message}`);
    if (tries >= TRIES) stop(`it could not register again: ${error.message}`);
  } finally {
    registering = false;
  }
}

setInterval(() => {
  const sentFor = registration;
  heartbeat.callService(
    {},
    () => {},
    (error) => {
      const reason = String(error);
      if (reason.includes("was deregistered")) stop(reason); // removed on purpose: do not come back
      if (reason.includes("advertise the service")) stop(reason); // it provides another service than it registered
      if (sentFor !== registration || registering) return;
      if (reason.includes("this session has no live component")) registerAgain(reason); // the lease lapsed
      else console.error(`thermometer: heartbeat: ${reason}`);
    },
    LEASE,
  );
}, (LEASE * 1000) / 3);
