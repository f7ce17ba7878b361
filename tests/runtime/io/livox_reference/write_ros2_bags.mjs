// Writes the Livox reference ROS 2 bags read by test_livox_import: livox.mcap with the MCAP project's own
// writer (@mcap/core) and livox.db3 (rosbag2's sqlite3 layout, through sql.js), every message serialized
// by Foxglove's ROS 2 CDR serializer (@foxglove/rosmsg2-serialization) from the .msg definitions below,
// so that our CDR decoder is checked against bytes it did not lay out itself. Also writes frames.json,
// the scans as numbers, from which write_ros1_bag.py writes the same recording as a ROS 1 bag.
//
// Each bag: three scans of a Livox LiDAR, each as livox_ros_driver2/msg/CustomMsg on /livox/lidar and as
// the driver's sensor_msgs/msg/PointCloud2 (x, y, z, intensity float32, tag, line uint8, timestamp
// float64 absolute nanoseconds, 26 bytes a point) on /livox/points; an 8x6 mono8 image after each scan on
// /camera/image_raw; and two garbled CustomMsgs on /livox/lidar: one cut short within its points, one
// whose point_num is not its number of points.
//
// Regenerate (README.md): cd tests/runtime/io/livox_reference && npm ci && node write_ros2_bags.mjs &&
//   rm -rf node_modules
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import { McapWriter } from "@mcap/core";
import initSqlJs from "sql.js";
import { writeFileSync } from "node:fs";

const HEADER_MSG = `MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
`;
const SEPARATOR = "================================================================================\n";
const CUSTOM_MSG = `std_msgs/Header header
uint64 timebase
uint32 point_num
uint8 lidar_id
uint8[3] rsvd
CustomPoint[] points
${SEPARATOR}${HEADER_MSG}${SEPARATOR}MSG: livox_ros_driver2/CustomPoint
uint32 offset_time
float32 x
float32 y
float32 z
uint8 reflectivity
uint8 tag
uint8 line
`;
const CLOUD_MSG = `std_msgs/Header header
uint32 height
uint32 width
PointField[] fields
bool is_bigendian
uint32 point_step
uint32 row_step
uint8[] data
bool is_dense
${SEPARATOR}${HEADER_MSG}${SEPARATOR}MSG: sensor_msgs/PointField
uint8 INT8    = 1
uint8 UINT8   = 2
uint8 INT16   = 3
uint8 UINT16  = 4
uint8 INT32   = 5
uint8 UINT32  = 6
uint8 FLOAT32 = 7
uint8 FLOAT64 = 8
string name
uint32 offset
uint8 datatype
uint32 count
`;
const IMAGE_MSG = `std_msgs/Header header
uint32 height
uint32 width
string encoding
uint8 is_bigendian
uint32 step
uint8[] data
${SEPARATOR}${HEADER_MSG}`;

const TOPICS = [
  { name: "/livox/lidar", type: "livox_ros_driver2/msg/CustomMsg", definition: CUSTOM_MSG },
  { name: "/livox/points", type: "sensor_msgs/msg/PointCloud2", definition: CLOUD_MSG },
  { name: "/camera/image_raw", type: "sensor_msgs/msg/Image", definition: IMAGE_MSG },
];
const WRITERS = Object.fromEntries(TOPICS.map((t) => [t.name, new MessageWriter(parse(t.definition, { ros2: true }))]));

const BASE_NS = 1700000000n * 1000000000n + 123456789n;
const SCANS = 3;
const POINTS = 300;

// A deterministic generator (a 32-bit LCG), so that a rerun writes the same files.
let seed = 12345;
function random() {
  seed = (Math.imul(seed, 1664525) + 1013904223) >>> 0;
  return seed / 4294967296;
}

// Scan k: 300 points 5 us apart on 4 lines, a few without a return (NaN, or at the origin, as Livox
// reports them), float32 coordinates.
function makeScan(k) {
  const timebase = BASE_NS + BigInt(k) * 100000000n;
  const points = [];
  for (let i = 0; i < POINTS; ++i) {
    const range = 2 + 20 * random();
    const azimuth = -Math.PI / 3 + ((2 * Math.PI) / 3) * random();
    const elevation = -0.6 + 1.2 * random();
    let xyz = [range * Math.cos(elevation) * Math.cos(azimuth), range * Math.cos(elevation) * Math.sin(azimuth),
               range * Math.sin(elevation)].map(Math.fround);
    if (i % 97 === 13) xyz = [NaN, NaN, NaN];
    if (i % 101 === 50) xyz = [0, 0, 0];
    points.push({ offset_time: i * 5000 + k, x: xyz[0], y: xyz[1], z: xyz[2], reflectivity: (i * 37 + k) % 256,
                  tag: i % 3 === 0 ? 0x10 : 0, line: i % 4 });
  }
  return { timebase, stamp: { sec: Number(timebase / 1000000000n), nanosec: Number(timebase % 1000000000n) },
           frame_id: "livox_frame", points };
}

function customMsg(scan, pointNum = scan.points.length) {
  return { header: { stamp: scan.stamp, frame_id: scan.frame_id }, timebase: scan.timebase, point_num: pointNum,
           lidar_id: 1, rsvd: [0, 0, 0], points: scan.points };
}

// livox_ros_driver2's PointCloud2 (xfer_format 0): LivoxPointXyzrtlt, packed.
function pointCloud2(scan) {
  const step = 26;
  const data = new Uint8Array(step * scan.points.length);
  const view = new DataView(data.buffer);
  scan.points.forEach((p, i) => {
    const at = i * step;
    [p.x, p.y, p.z, p.reflectivity].forEach((v, j) => view.setFloat32(at + 4 * j, v, true));
    view.setUint8(at + 16, p.tag);
    view.setUint8(at + 17, p.line);
    view.setFloat64(at + 18, Number(scan.timebase + BigInt(p.offset_time)), true);
  });
  const field = (name, offset, datatype) => ({ name, offset, datatype, count: 1 });
  return { header: { stamp: scan.stamp, frame_id: scan.frame_id }, height: 1, width: scan.points.length,
           fields: [field("x", 0, 7), field("y", 4, 7), field("z", 8, 7), field("intensity", 12, 7),
                    field("tag", 16, 2), field("line", 17, 2), field("timestamp", 18, 8)],
           is_bigendian: false, point_step: step, row_step: step * scan.points.length, data, is_dense: true };
}

function image(k, stamp) {
  return { header: { stamp, frame_id: "camera" }, height: 6, width: 8, encoding: "mono8", is_bigendian: 0, step: 8,
           data: Uint8Array.from({ length: 48 }, (_, j) => (k * 40 + j * 5) & 0xff) };
}

function toStamp(ns) {
  return { sec: Number(ns / 1000000000n), nanosec: Number(ns % 1000000000n) };
}

// The messages in log-time order: each scan on both topics 5 ms after its stamp, an image 20 ms after
// it, and the garbled CustomMsgs after the second and third scans.
function messagePlan(scans) {
  const plan = [];
  const add = (topic, logTime, bytes) => plan.push({ topic, logTime, data: bytes });
  scans.forEach((scan, k) => {
    const custom = WRITERS["/livox/lidar"].writeMessage(customMsg(scan));
    add("/livox/lidar", scan.timebase + 5000000n, custom);
    add("/livox/points", scan.timebase + 5000000n, WRITERS["/livox/points"].writeMessage(pointCloud2(scan)));
    add("/camera/image_raw", scan.timebase + 20000000n,
        WRITERS["/camera/image_raw"].writeMessage(image(k, toStamp(scan.timebase + 15000000n))));
    if (k === 1) add("/livox/lidar", scan.timebase + 30000000n, custom.slice(0, 4 + 44 + 20 * 150 + 7));
    if (k === 2)
      add("/livox/lidar", scan.timebase + 30000000n,
          WRITERS["/livox/lidar"].writeMessage(customMsg(scan, scan.points.length + 5)));
  });
  return plan;
}

// An IWritable collecting the file in memory.
class MemoryWritable {
  chunks = [];
  length = 0n;
  position() {
    return this.length;
  }
  async write(buffer) {
    this.chunks.push(Buffer.from(buffer));
    this.length += BigInt(buffer.byteLength);
  }
  bytes() {
    return Buffer.concat(this.chunks);
  }
}

const QOS = "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n";

async function writeMcap(plan, path) {
  const out = new MemoryWritable();
  const writer = new McapWriter({ writable: out, useChunks: true, chunkSize: 64 * 1024 });
  await writer.start({ profile: "ros2", library: "@mcap/core (fusecal livox_reference)" });
  const ids = {};
  for (const topic of TOPICS) {
    const schemaId = await writer.registerSchema({ name: topic.type, encoding: "ros2msg",
                                                   data: new TextEncoder().encode(topic.definition) });
    ids[topic.name] = await writer.registerChannel({ topic: topic.name, schemaId, messageEncoding: "cdr",
                                                     metadata: new Map([["offered_qos_profiles", QOS]]) });
  }
  let sequence = 0;
  for (const m of plan)
    await writer.addMessage({ channelId: ids[m.topic], sequence: sequence++, logTime: m.logTime,
                              publishTime: m.logTime, data: m.data });
  await writer.end();
  writeFileSync(path, out.bytes());
}

// rosbag2's sqlite3 storage (ROS 2 Humble's schema).
async function writeDb3(plan, path) {
  const SQL = await initSqlJs();
  const db = new SQL.Database();
  db.run(`CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
          serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
          CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,
          data BLOB NOT NULL);
          CREATE INDEX timestamp_idx ON messages (timestamp ASC);`);
  TOPICS.forEach((t, i) => db.run("INSERT INTO topics VALUES (?, ?, ?, 'cdr', ?)", [i + 1, t.name, t.type, QOS]));
  const ids = Object.fromEntries(TOPICS.map((t, i) => [t.name, i + 1]));
  // sql.js binds a JS number: log times (1.7e18 ns) exceed 2^53, so they go in as SQL text casts.
  plan.forEach((m, i) =>
    db.run(`INSERT INTO messages VALUES (?, ?, CAST('${m.logTime}' AS INTEGER), ?)`, [i + 1, ids[m.topic], m.data]));
  writeFileSync(path, Buffer.from(db.export()));
  db.close();
}

function writeFrames(scans, path) {
  const json = scans.map((s) => ({ timebase: s.timebase.toString(), sec: s.stamp.sec, nanosec: s.stamp.nanosec,
                                   frame_id: s.frame_id,
                                   points: s.points.map((p) => [p.offset_time, p.x, p.y, p.z, p.reflectivity, p.tag, p.line]) }));
  writeFileSync(path, JSON.stringify({ scans: json }) + "\n");
}

const scans = Array.from({ length: SCANS }, (_, k) => makeScan(k));
const plan = messagePlan(scans);
writeFrames(scans, "frames.json");
await writeMcap(plan, "livox.mcap");
await writeDb3(plan, "livox.db3");
console.log(`wrote livox.mcap, livox.db3 (${plan.length} messages) and frames.json`);
