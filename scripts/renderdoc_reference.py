#!/usr/bin/python3
"""RenderDoc's own account of a capture, for framelab's RenderDoc import tests.

Usage: /usr/bin/python3 scripts/renderdoc_reference.py CAPTURE.rdc

Writes CAPTURE.rdc.renderdoc.json (what RenderDoc lists: actions counted by kind, each
draw's index and instance counts, textures and buffers with formats and sizes, the
pipeline barriers recorded in the frame) and CAPTURE.rdc.ref.png (the presented image as
RenderDoc's replay shows it at the present, read with GetTextureData). Needs RenderDoc's
Python module (Debian's renderdoc package, for /usr/bin/python3) and a Vulkan device
(lavapipe will do).
"""
import json
import struct
import sys
import zlib

import renderdoc as rd


def write_png(path, width, height, rows):
    def chunk(tag, data):
        body = tag + data
        return struct.pack('>I', len(data)) + body + struct.pack('>I', zlib.crc32(body) & 0xffffffff)
    raw = b''.join(b'\x00' + r for r in rows)
    with open(path, 'wb') as f:
        f.write(b'\x89PNG\r\n\x1a\n'
                + chunk(b'IHDR', struct.pack('>IIBBBBB', width, height, 8, 6, 0, 0, 0))
                + chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))


def main(path):
    rd.InitialiseReplay(rd.GlobalEnvironment(), [])
    cap = rd.OpenCaptureFile()
    if not cap.OpenFile(path, '', None).OK():
        raise SystemExit('cannot open ' + path)
    status, controller = cap.OpenCapture(rd.ReplayOptions(), None)
    if not status.OK():
        raise SystemExit('cannot replay ' + path)
    sf = controller.GetStructuredFile()
    flags = rd.ActionFlags
    counts = dict(draws=0, dispatches=0, clears=0, render_passes=0, copies=0, presents=0)
    draws, present = [], None

    def walk(a):
        nonlocal present
        f = a.flags
        if f & flags.Drawcall:
            counts['draws'] += 1
            draws.append({'indices': int(a.numIndices), 'instances': int(a.numInstances)})
        if f & flags.Dispatch:
            counts['dispatches'] += 1
        if f & flags.Clear:
            counts['clears'] += 1
        # A command buffer's start is a pass boundary too; only render passes count.
        if f & flags.BeginPass and not f & flags.CommandBufferBoundary:
            counts['render_passes'] += 1
        if f & flags.Copy:
            counts['copies'] += 1
        if f & flags.Present:
            counts['presents'] += 1
            present = a
        for c in a.children:
            walk(c)

    for a in controller.GetRootActions():
        walk(a)

    barriers, in_frame = [], False
    for ch in sf.chunks:
        if ch.name == 'Internal::Beginning of Capture':
            in_frame = True
        if in_frame and ch.name.startswith('vkCmdPipelineBarrier'):
            n = lambda key: int(ch.FindChildRecursively(key).AsInt())
            barriers.append({'image': n('imageMemoryBarrierCount'),
                             'buffer': n('bufferMemoryBarrierCount'),
                             'memory': n('memoryBarrierCount')})

    textures = controller.GetTextures()
    out = {
        'renderdoc': rd.GetVersionString(),
        'frame': int(controller.GetFrameInfo().frameNumber),
        'counts': counts,
        'draws': draws,
        'textures': sorted(({'format': t.format.Name(), 'width': int(t.width),
                             'height': int(t.height), 'depth': int(t.depth), 'mips': int(t.mips),
                             'layers': int(t.arraysize), 'samples': int(t.msSamp),
                             'swapchain': bool(t.creationFlags & rd.TextureCategory.SwapBuffer)}
                            for t in textures), key=json.dumps),
        'buffers': sorted(int(b.length) for b in controller.GetBuffers()),
        'barriers': barriers,
    }
    if present is not None:
        image = present.copyDestination
        tex = [t for t in textures if t.resourceId == image][0]
        controller.SetFrameEvent(int(present.eventId), True)
        data = bytes(controller.GetTextureData(image, rd.Subresource()))
        fmt, w, h = tex.format, int(tex.width), int(tex.height)
        if not (fmt.type == rd.ResourceFormatType.Regular and fmt.compByteWidth == 1 and fmt.compCount == 4):
            raise SystemExit('presented format %s is not 8-bit RGBA' % fmt.Name())
        rows = []
        for y in range(h):
            r = bytearray(data[y * w * 4:(y + 1) * w * 4])
            if fmt.BGRAOrder():
                r[0::4], r[2::4] = r[2::4], r[0::4]
            r[3::4] = b'\xff' * w  # the compositor ignores the presented alpha
            rows.append(bytes(r))
        write_png(path + '.ref.png', w, h, rows)
        out['presented'] = {'format': fmt.Name(), 'width': w, 'height': h}
    with open(path + '.renderdoc.json', 'w') as f:
        json.dump(out, f, indent=1, sort_keys=True)
        f.write('\n')
    controller.Shutdown()
    cap.Shutdown()
    rd.ShutdownReplay()


if __name__ == '__main__':
    main(sys.argv[1])
