"""One MCP session with `framelab mcp`, held by the official Python SDK's client (an
independent implementation of the protocol): initialize, tools/list, every tool on the
bundled captures, bad input of each kind, then shutdown by closing stdin. Prints one JSON
object: what each call answered, for the Rust test to compare with the command line.

Usage: python3 session.py <framelab binary> <repository root> <folder for the images>
       [<folder inside the repository for capture_program>]
"""

import asyncio
import base64
import json
import os
import sys
from pathlib import Path

import mcp.types as types
from mcp import ClientSession, StdioServerParameters
from mcp.client.stdio import stdio_client

import anyio

FRAMELAB, REPO, IMAGES = sys.argv[1], Path(sys.argv[2]).resolve(), Path(sys.argv[3])


async def roots(_context):
    # The client lets the server read the repository only.
    return types.ListRootsResult(roots=[types.Root(uri=REPO.as_uri(), name="repository")])


def outcome(result):
    """A call's answer: its structured content, or its error text."""
    text = "".join(c.text for c in result.content if getattr(c, "type", "") == "text")
    if result.is_error:
        return {"error": text}
    return {"ok": result.structured_content}


async def main():
    # The SDK passes the server only a few variables of its own environment; vkcube (run by
    # capture_program) needs the display.
    env = {k: os.environ[k] for k in ["DISPLAY"] if k in os.environ}
    server = StdioServerParameters(command=FRAMELAB, args=["mcp"], cwd=str(REPO), env=env)
    out = {}
    # The server's log (stderr), where a cancelled replay says where it stopped.
    log = open(IMAGES / "server.log", "w")
    async with stdio_client(server, errlog=log) as (read, write):
        async with ClientSession(read, write, list_roots_callback=roots) as session:
            init = await session.initialize()
            out["server"] = init.server_info.name
            tools = await session.list_tools()
            out["tools"] = sorted(t.name for t in tools.tools)
            out["schemas"] = {t.name: t.input_schema for t in tools.tools}

            async def call(name, **arguments):
                return outcome(await session.call_tool(name, arguments))

            day = await call("open_capture", path="captures/night_city/main_street_day.json", scale=0.25)
            example = await call("open_capture", path="captures/example/frame.json")
            sync = await call("open_capture", path="captures/example/frame_sync.json")
            out["open"] = {"day": day, "example": example}
            d, e, s = (x["ok"]["capture"] for x in (day, example, sync))
            # Every pass of the day frame, paged as a client would.
            rows, offset = [], 0
            while True:
                page = await call("list_passes", capture=d, offset=offset, limit=40)
                rows += page["ok"]["rows"]
                offset += 40
                if offset >= page["ok"]["total"]:
                    break
            out["day_passes"] = rows
            out["example_resources"] = await call("list_resources", capture=e, limit=1000)
            out["filtered"] = await call("list_passes", capture=d, filter="csm_")
            # `pass` is a Python keyword: this call passes its arguments as a dict.
            out["ssr_trace"] = outcome(await session.call_tool("pass_details", {"capture": d, "pass": "ssr_trace"}))
            out["analyze"] = await call("analyze", capture=e)
            out["analyze_cull"] = await call("analyze", capture=e, cull=True)
            out["diff"] = await call("diff", a=e, b=s, mode="structure")
            # Bad input: each a tool error naming what is wrong; the next call still answers.
            out["bad"] = {
                "unknown_capture": await call("list_passes", capture="c99"),
                "unknown_pass": await session.call_tool("pass_details", {"capture": d, "pass": "ssr_trac"}),
                "schema": await session.call_tool("list_passes", {"capture": 7}),
                "unknown_field": await session.call_tool("list_passes", {"capture": d, "colour": "red"}),
                "bad_mode": await call("diff", a=e, b=s, mode="pixels"),
                "outside_roots": await call("open_capture", path="/etc/passwd"),
                "does_not_load": await call("open_capture", path="tests/invalid/copy_overrun.json"),
                "too_many_rows": await call("list_passes", capture=d, limit=100000),
            }
            out["bad"] = {k: v if isinstance(v, dict) else outcome(v) for k, v in out["bad"].items()}
            out["after_bad"] = await call("list_passes", capture=e, limit=1)

            s2 = (await call("open_capture", path="captures/example/frame_sync.json"))["ok"]["capture"]
            # What `framelab import` reads, opened directly.
            out["imports"] = {}
            for name in ["vkcube_f3.gfxr", "vkcube_f3.jsonl"]:
                opened = await call("open_capture", path=f"tests/fixtures/gfxr/{name}")
                rows = await call("list_passes", capture=opened["ok"]["capture"], limit=1000)
                out["imports"][name] = {"open": opened, "passes": rows}
                await call("close_capture", capture=opened["ok"]["capture"])
            # Textures, replayed: the progress each call reports, the summary, the PNG saved.
            async def texture(name, **arguments):
                progress = []

                async def on_progress(done, total, message):
                    progress.append([done, total])

                result = await session.call_tool("texture", arguments, progress_callback=on_progress)
                answer = outcome(result)
                for c in result.content:
                    if c.type == "image":
                        (IMAGES / f"{name}.png").write_bytes(base64.b64decode(c.data))
                        answer["mime"] = c.mime_type
                answer["progress"] = progress
                return answer

            out["textures"] = {
                "ldr": await texture("ldr", capture=e, resource="ldr", after_pass="tonemap"),
                "ldr_again": await texture("ldr_again", capture=e, resource="ldr", after_pass="tonemap"),
                "albedo": await texture("albedo", capture=d, resource="gbuffer_albedo", after_pass="base_material"),
                "albedo_small": await texture("albedo_small", capture=d, resource="gbuffer_albedo", after_pass="base_material", max_size=100),
                "albedo_before": await texture("albedo_before", capture=d, resource="gbuffer_albedo", after_pass="depth_prepass"),
                "buffer": await texture("buffer", capture=e, resource="particles"),
                "texels": await call("read_texels", capture=e, resource="ldr", after_pass="tonemap", x=10, y=20, width=3, height=2),
                "texels_too_many": await call("read_texels", capture=e, resource="ldr", x=0, y=0, width=100, height=100),
                "texels_outside": await call("read_texels", capture=e, resource="ldr", x=100000, y=0),
                "args_cleared": await call("read_buffer", capture=e, resource="draw_args", after_pass="reset_args"),
                "args": await call("read_buffer", capture=e, resource="draw_args", after_pass="simulate"),
                "particles": await call("read_buffer", capture=e, resource="particles", after_pass="simulate", offset=16, length=64),
                "buffer_texture": await call("read_buffer", capture=e, resource="ldr"),
                "buffer_too_long": await call("read_buffer", capture=e, resource="particles", length=1 << 20),
                "bad_mip": await texture("bad_mip", capture=e, resource="ldr", mip=3),
                "bad_size": await texture("bad_size", capture=e, resource="ldr", max_size=100000),
            }
            progress = []

            async def on_frame(done, total, message):
                progress.append([done, total])

            out["timings"] = outcome(await session.call_tool("timings", {"capture": e, "frames": 2}, progress_callback=on_frame))
            out["timings"]["progress"] = progress
            out["timings_bad"] = await call("timings", capture=e, frames=1000)
            out["diff_timing"] = await call("diff", a=e, b=s2, mode="timing", frames=3)
            out["diff_structure_frames"] = await call("diff", a=e, b=s2, mode="structure", frames=3)
            out["diff_work"] = await call("diff", a=e, b=s2, mode="work")
            out["timings_counted"] = await call("timings", capture=e, frames=1, counters=True)
            # What if bloom were R11G11B10_FLOAT; a barrier dropped; an edit naming nothing.
            what = await session.call_tool("what_if", {"capture": s, "format": ["bloom=R11G11B10_FLOAT"], "frames": 2})
            out["what_if"] = outcome(what)
            out["what_if"]["images"] = [c.mime_type for c in what.content if c.type == "image"]
            out["what_if_unsafe"] = await call("what_if", capture=s, drop_barrier=["simulate:0"])
            out["what_if_bad"] = await call("what_if", capture=s, cull=["nope"])
            # A frame of a running program, taken into a folder inside the roots.
            if len(sys.argv) > 4:
                out["capture_program"] = await call("capture_program", program="vkcube", frame=3, dir=sys.argv[4], timeout=120)
                if "ok" in out["capture_program"]:
                    taken = out["capture_program"]["ok"]["capture"]
                    out["captured_passes"] = await call("list_passes", capture=taken)
                out["capture_outside"] = await call("capture_program", program="vkcube", frame=3, dir="/tmp")
            # A replay cancelled by the client stops; the next request is answered.
            night = await call("open_capture", path="captures/night_city/river_bank_night.json", scale=0.25)
            assert "ok" in night, night
            with anyio.move_on_after(0.5):
                await session.call_tool("texture", {"capture": night["ok"]["capture"], "resource": "gbuffer_albedo"})
            out["after_cancel"] = await call("list_passes", capture=e, limit=1)
            # The worker may still be setting the replay up when the request is cancelled (a
            # slow machine): the session stays open until its log says where the replay stopped.
            with anyio.move_on_after(600):
                while "replay cancelled" not in (IMAGES / "server.log").read_text():
                    await anyio.sleep(0.2)
            out["closed"] = await call("close_capture", capture=s)
            out["after_close"] = await call("list_passes", capture=s)
    print(json.dumps(out))


asyncio.run(main())
