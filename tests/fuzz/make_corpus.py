#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes the fuzzers' seed corpus (tests/fuzz/corpus/): a few inputs that
reach deep into each target, so that a minute of fuzzing starts from markers
rather than from noise. Run it again after changing a target's input layout.
"""
import os
import random
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
DICTS = os.path.join(HERE, '..', '..', 'frappe-core', 'dictionaries')


def dictionary_names():
    # frappe::dictionaries() lists them in the order of the generated table:
    # the file names sorted (frappe-core/gen_dictionaries.py).
    return sorted(f[:-4] for f in os.listdir(DICTS) if f.endswith('.txt'))


def code(name, idx):
    lines = [l.split()[0] for l in open(os.path.join(DICTS, name + '.txt')) if l.strip() and not l.startswith('#')]
    return int(lines[idx], 16)


def marker(size, bits, value, cell, at, white=230, black=20):
    img = [[white] * size for _ in range(size)]
    n = bits + 2
    for cy in range(n):
        for cx in range(n):
            if cx in (0, n - 1) or cy in (0, n - 1):
                v = black
            else:
                bit = (bits * bits - 1) - ((cy - 1) * bits + (cx - 1))
                v = white if (value >> bit) & 1 else black
            for y in range(cell):
                for x in range(cell):
                    img[at + cy * cell + y][at + cx * cell + x] = v
    return img


def blur(img):
    h, w = len(img), len(img[0])
    out = [row[:] for row in img]
    for y in range(1, h - 1):
        for x in range(1, w - 1):
            out[y][x] = sum(img[y + dy][x + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1)) // 9
    return out


def detect_seed(path, img, dict_index, flags, pad=0, frames=1):
    h, w = len(img), len(img[0])
    head = bytes([(w - 1) % 192, (h - 1) % 192, pad, flags, dict_index, frames - 1])
    with open(path, 'wb') as f:
        f.write(head + bytes(v for row in img for v in row))


def main():
    names = dictionary_names()
    out = os.path.join(HERE, 'corpus', 'detect')
    os.makedirs(out, exist_ok=True)
    small = names.index('4x4_50')
    mip = names.index('aruco_mip_36h12')
    detect_seed(os.path.join(out, 'marker-4x4'), marker(96, 4, code('4x4_50', 0), 8, 16), small, 0)
    detect_seed(os.path.join(out, 'marker-4x4-blur-regions'), blur(marker(96, 4, code('4x4_50', 7), 8, 16)),
                small, 2)
    detect_seed(os.path.join(out, 'marker-mip-ascale'), marker(128, 6, code('aruco_mip_36h12', 3), 10, 24),
                mip, 1, pad=3, frames=2)
    rng = random.Random(1)
    detect_seed(os.path.join(out, 'noise'), [[rng.randrange(256) for _ in range(64)] for _ in range(48)], mip, 2)

    out = os.path.join(HERE, 'corpus', 'config')
    os.makedirs(out, exist_ok=True)
    for i, name in enumerate([b'aruco_mip_36h12', b'DICT_4X4_50', b'tag36h11', b'nope']):
        # In LLVMFuzzerTestOneInput's order: the name, "use a real name
        # instead" (no), the mode, the fields at their typical values
        # (selector 0; max_hamming 2, max_scaled_frames 5, threads 1, the
        # default max_pixels), a 64 x 48 frame of stride 64, the pipeline mode.
        typical = bytes([0]) + struct.pack('<f', 0.0)
        body = bytes([len(name)]) + name + bytes([0, i & 1])
        body += typical * 2 + struct.pack('<b', 2) + typical * 2 + struct.pack('<h', 5)
        body += typical * 3 + struct.pack('<b', 1) + bytes([0])
        body += struct.pack('<hhb', 64, 48, 0) + bytes([i & 1])
        with open(os.path.join(out, 'config-%d' % i), 'wb') as f:
            f.write(body)

    # Dictionary files as a user writes them: the text format with and
    # without its header, OpenCV's YAML and XML.
    out = os.path.join(HERE, 'corpus', 'dictionary')
    os.makedirs(out, exist_ok=True)
    codes = [code('4x4_50', i) for i in range(5)]
    seeds = {
        'text-header': '# dictionary: mine\n# marker_side_bits: 4\n# codes: 5\n' +
                       ''.join('0x%04x\n' % c for c in codes),
        'text-bare': '\r\n'.join('0x%04x' % c for c in codes),
        'opencv-yml': '%%YAML:1.0\n---\nnmarkers: 5\nmarkersize: 4\nmaxCorrectionBits: 1\n' +
                      ''.join('marker_%d: "%s"\n' % (i, format(c, '016b')) for i, c in enumerate(codes)),
        'opencv-xml': '<?xml version="1.0"?>\n<opencv_storage>\n<nmarkers>5</nmarkers>\n<markersize>4</markersize>\n' +
                      ''.join('<marker_%d>"%s"</marker_%d>\n' % (i, format(c, '016b'), i) for i, c in enumerate(codes)) +
                      '</opencv_storage>\n',
    }
    for name, text in seeds.items():
        with open(os.path.join(out, name), 'w', newline='') as f:
            f.write(text)

    # Calibration files as tools write them: the samples' ROS camera_info
    # and OpenCV FileStorage YAML, OpenCV's XML, a CameraInfo message.
    out = os.path.join(HERE, 'corpus', 'calibration')
    os.makedirs(out, exist_ok=True)
    data = os.path.join(HERE, '..', '..', 'examples', 'data')
    seeds = {name: open(os.path.join(data, name)).read() for name in ('camera-700.yaml', 'camera-700-opencv.yml')}
    seeds['opencv.xml'] = (
        '<?xml version="1.0"?>\n<opencv_storage>\n<image_width>1280</image_width>\n'
        '<image_height>720</image_height>\n<!-- a comment -->\n<camera_matrix type_id="opencv-matrix">\n'
        '  <rows>3</rows>\n  <cols>3</cols>\n  <dt>d</dt>\n'
        '  <data>9.12e+02 0. 6.40e+02 0. 9.13e+02 3.60e+02 0. 0. 1.</data></camera_matrix>\n'
        '<distortion_coefficients type_id="opencv-matrix">\n  <rows>1</rows>\n  <cols>5</cols>\n'
        '  <dt>d</dt>\n  <data>1.2e-01 -2.3e-01 1.e-03 -2.e-03 &amp; 9.8e-02</data></distortion_coefficients>\n'
        '</opencv_storage>\n')
    seeds['camera-info-message'] = (
        'header: \n  seq: 12\n  frame_id: "camera"\nheight: 480\nwidth: 640\n'
        'distortion_model: "rational_polynomial"\nD: [0.35, -0.12, 0.0009, 0.0005, 0.02, 0.62, -0.06, 0.03]\n'
        'K: [690.0, 0.0, 322.0, 0.0, 705.0, 236.0, 0.0, 0.0, 1.0]\n'
        'camera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: {a: 1}\n')
    for name, text in seeds.items():
        with open(os.path.join(out, name), 'w', newline='') as f:
            f.write(text)


if __name__ == '__main__':
    main()
