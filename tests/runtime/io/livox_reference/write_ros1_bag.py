#!/usr/bin/python3
"""Writes livox.bag, the ROS 1 form of the Livox reference recording (write_ros2_bags.mjs writes the ROS 2
forms and frames.json, which this script reads), with ROS's own Python bag writer (Debian's
python3-rosbag) and message classes that ROS's genpy generates from the .msg definitions below, so that
our ROS 1 decoding is checked against bytes it did not lay out itself.

The same messages as the ROS 2 bags: three scans as livox_ros_driver2/CustomMsg on /livox/lidar and as
the driver's sensor_msgs/PointCloud2 on /livox/points, an 8x6 mono8 image after each on
/camera/image_raw, and two garbled CustomMsgs (one cut short within its points, one whose point_num is
not its number of points).

Regenerate (README.md): in this folder, apt-get install $(cat ros1_writer_debian_packages.txt), then
  /usr/bin/python3 write_ros1_bag.py
"""
import json
import math
import struct
from io import BytesIO

import genpy
import genpy.dynamic
import rosbag

SEPARATOR = "=" * 80 + "\n"
HEADER_MSG = "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n"
CUSTOM_MSG = (
    "std_msgs/Header header\nuint64 timebase\nuint32 point_num\nuint8 lidar_id\nuint8[3] rsvd\n"
    "CustomPoint[] points\n" + SEPARATOR + HEADER_MSG + SEPARATOR + "MSG: livox_ros_driver2/CustomPoint\n"
    "uint32 offset_time\nfloat32 x\nfloat32 y\nfloat32 z\nuint8 reflectivity\nuint8 tag\nuint8 line\n")
CLOUD_MSG = (
    "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\n"
    "uint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n" + SEPARATOR + HEADER_MSG + SEPARATOR +
    "MSG: sensor_msgs/PointField\nuint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\n"
    "uint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n")
IMAGE_MSG = ("std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n"
             "uint32 step\nuint8[] data\n" + SEPARATOR + HEADER_MSG)

CUSTOM = genpy.dynamic.generate_dynamic("livox_ros_driver2/CustomMsg", CUSTOM_MSG)
CLOUD = genpy.dynamic.generate_dynamic("sensor_msgs/PointCloud2", CLOUD_MSG)
IMAGE = genpy.dynamic.generate_dynamic("sensor_msgs/Image", IMAGE_MSG)


def stamp(ns):
    return genpy.Time(ns // 1000000000, ns % 1000000000)


def header(types, ns, frame_id):
    return types["std_msgs/Header"](seq=0, stamp=stamp(ns), frame_id=frame_id)


def coordinate(value):
    return math.nan if value is None else value  # JSON has no NaN: write_ros2_bags.mjs wrote null


def custom_msg(scan, point_num=None):
    point_type = CUSTOM["livox_ros_driver2/CustomPoint"]
    points = [point_type(offset_time=p[0], x=coordinate(p[1]), y=coordinate(p[2]), z=coordinate(p[3]),
                         reflectivity=p[4], tag=p[5], line=p[6]) for p in scan["points"]]
    return CUSTOM["livox_ros_driver2/CustomMsg"](
        header=header(CUSTOM, scan["timebase"], scan["frame_id"]), timebase=scan["timebase"],
        point_num=len(points) if point_num is None else point_num, lidar_id=1, rsvd=[0, 0, 0], points=points)


def point_cloud2(scan):
    """livox_ros_driver2's PointCloud2 (xfer_format 0): LivoxPointXyzrtlt, packed into 26 bytes."""
    data = b"".join(struct.pack("<ffffBBd", coordinate(p[1]), coordinate(p[2]), coordinate(p[3]), p[4], p[5], p[6],
                                float(scan["timebase"] + p[0])) for p in scan["points"])
    field = CLOUD["sensor_msgs/PointField"]
    fields = [field(name="x", offset=0, datatype=7, count=1), field(name="y", offset=4, datatype=7, count=1),
              field(name="z", offset=8, datatype=7, count=1), field(name="intensity", offset=12, datatype=7, count=1),
              field(name="tag", offset=16, datatype=2, count=1), field(name="line", offset=17, datatype=2, count=1),
              field(name="timestamp", offset=18, datatype=8, count=1)]
    n = len(scan["points"])
    return CLOUD["sensor_msgs/PointCloud2"](
        header=header(CLOUD, scan["timebase"], scan["frame_id"]), height=1, width=n, fields=fields,
        is_bigendian=False, point_step=26, row_step=26 * n, data=data, is_dense=True)


def image(k, ns):
    return IMAGE["sensor_msgs/Image"](header=header(IMAGE, ns, "camera"), height=6, width=8, encoding="mono8",
                                      is_bigendian=0, step=8, data=bytes((k * 40 + j * 5) & 0xFF for j in range(48)))


def serialized(msg):
    buffer = BytesIO()
    msg.serialize(buffer)
    return buffer.getvalue()


def write_garbled(bag, msg, data, ns):
    bag.write("/livox/lidar", (msg._type, data, msg._md5sum, type(msg)), stamp(ns), raw=True)


def main():
    with open("frames.json") as f:
        scans = json.load(f)["scans"]
    for scan in scans:
        scan["timebase"] = int(scan["timebase"])
    with rosbag.Bag("livox.bag", "w") as bag:
        for k, scan in enumerate(scans):
            t = scan["timebase"]
            custom = custom_msg(scan)
            bag.write("/livox/lidar", custom, stamp(t + 5000000))
            bag.write("/livox/points", point_cloud2(scan), stamp(t + 5000000))
            bag.write("/camera/image_raw", image(k, t + 15000000), stamp(t + 20000000))
            if k == 1:  # cut short within point 150: header 4 + 4 + 4 + 4 + 11 bytes, then 16 bytes, 19 a point
                write_garbled(bag, custom, serialized(custom)[:27 + 16 + 4 + 19 * 150 + 7], t + 30000000)
            if k == 2:
                garbled = custom_msg(scan, point_num=len(scan["points"]) + 5)
                write_garbled(bag, garbled, serialized(garbled), t + 30000000)
    print("wrote livox.bag")


if __name__ == "__main__":
    main()
