"""neepp view's web server (aiohttp): the page's three files and one websocket per open page, on
127.0.0.1 only.

Each page gets the session's state when it connects, then every frame; a page slower than the render
gets the newest frame when it is ready for one, not a backlog. Requests whose Host is not this server's
loopback address (a web page elsewhere reaching it by DNS rebinding) and websockets opened from another
origin are refused: the server renders and writes files on the user's behalf.
"""
from __future__ import annotations

import asyncio
from pathlib import Path

from aiohttp import WSMsgType, web

from . import messages
from .session import Frame, ViewSession

PAGE_DIR = Path(__file__).resolve().parent / "page"
PAGE_FILES = {"/": ("index.html", "text/html"), "/view.js": ("view.js", "text/javascript"),
              "/view.css": ("view.css", "text/css")}


class Client:
    """One open page: what is to be sent to it, by a task of its own, in order (messages first, then the
    newest frame), so that a slow page never holds up the others or the render."""

    def __init__(self, ws: web.WebSocketResponse):
        self.ws = ws
        self.texts: list = []  # JSON messages (dicts) and binary ones (bytes, e.g. a map view), in order
        self.frame: bytes | None = None
        self.wake = asyncio.Event()

    def send_text(self, msg: dict) -> None:
        self.texts.append(msg)
        self.wake.set()

    def send_binary(self, data: bytes) -> None:
        """A binary message that, unlike a frame, is never replaced by a newer one."""
        self.texts.append(data)
        self.wake.set()

    def send_frame(self, data: bytes) -> None:
        self.frame = data  # replaces one not sent yet
        self.wake.set()

    async def pump(self) -> None:
        try:
            while not self.ws.closed:
                await self.wake.wait()
                self.wake.clear()
                while self.texts:
                    msg = self.texts.pop(0)
                    if isinstance(msg, bytes):
                        await self.ws.send_bytes(msg)
                    else:
                        await self.ws.send_json(msg)
                if self.frame is not None:
                    data, self.frame = self.frame, None
                    await self.ws.send_bytes(data)
        except (ConnectionError, RuntimeError):  # the page went away mid-send: its handler ends too
            pass


class ViewServer:
    def __init__(self, session: ViewSession):
        self.session = session
        self.clients: set[Client] = set()
        self.loop: asyncio.AbstractEventLoop | None = None
        self.port = 0
        self.app = web.Application(middlewares=[self._only_this_host])
        self.app.router.add_get("/ws", self._websocket)
        for route in PAGE_FILES:
            self.app.router.add_get(route, self._page)

    # From the render thread: onto the server's loop.
    def _frame(self, frame: Frame) -> None:
        data = messages.encode_frame(frame.stats, frame.image.astype("<f4", copy=False).tobytes())
        self.loop.call_soon_threadsafe(self._broadcast_frame, data)

    def _message(self, msg: dict) -> None:
        self.loop.call_soon_threadsafe(self._broadcast_text, msg)

    def _broadcast_frame(self, data: bytes) -> None:
        for c in list(self.clients):
            c.send_frame(data)

    def _broadcast_text(self, msg: dict) -> None:
        for c in list(self.clients):
            c.send_text(msg)

    def _allowed_hosts(self) -> set[str]:
        return {f"127.0.0.1:{self.port}", f"localhost:{self.port}"}

    @web.middleware
    async def _only_this_host(self, request: web.Request, handler):
        if request.host not in self._allowed_hosts():
            raise web.HTTPForbidden(text="neepp view answers on its own loopback address only\n")
        return await handler(request)

    async def _page(self, request: web.Request) -> web.Response:
        name, content_type = PAGE_FILES[request.path]
        # The page may load nothing but its own files and talk to nothing but this server.
        csp = (f"default-src 'self'; img-src 'self' data: blob:; "
               f"connect-src 'self' ws://127.0.0.1:{self.port} ws://localhost:{self.port}")
        return web.Response(body=(PAGE_DIR / name).read_bytes(), content_type=content_type,
                            headers={"Cache-Control": "no-store", "Content-Security-Policy": csp})

    async def _websocket(self, request: web.Request) -> web.WebSocketResponse:
        origin = request.headers.get("Origin")
        if origin is not None and origin not in {f"http://{h}" for h in self._allowed_hosts()}:
            raise web.HTTPForbidden(text="websocket from another origin\n")
        ws = web.WebSocketResponse(max_msg_size=messages.MAX_MESSAGE_BYTES, heartbeat=30)
        await ws.prepare(request)
        client = Client(ws)
        self.clients.add(client)
        pump = asyncio.create_task(client.pump())
        client.send_text(self.session.state())
        if self.session.reference is not None:
            client.send_binary(messages.encode_reference(self.session.reference_name, self.session.reference))
        latest = self.session.latest
        if latest is not None:
            client.send_frame(messages.encode_frame(latest.stats, latest.image.astype("<f4", copy=False).tobytes()))
        try:
            async for msg in ws:
                if msg.type == WSMsgType.TEXT:
                    await self._command(client, msg.data)
                elif msg.type == WSMsgType.BINARY:
                    client.send_text({"type": "error", "message": "messages are JSON text"})
                elif msg.type == WSMsgType.ERROR:  # e.g. a message over the size limit: the socket closes
                    break
        finally:
            self.clients.discard(client)
            pump.cancel()
        return ws

    async def _command(self, client: Client, text: str) -> None:
        try:
            command = messages.parse(text)
        except messages.BadMessage as e:
            client.send_text({"type": "error", "message": str(e)})
            return
        kind = command["type"]
        if kind in messages.CAMERA_COMMANDS:
            self.session.camera_command(command)
        elif kind == "options":
            self.session.set_options(command["integrator"], command["options"])
        elif kind == "pick":
            # Answered by the render thread between passes (a pass's length at most): the image goes on.
            try:
                result, heat = await asyncio.wait_for(
                    asyncio.wrap_future(self.session.map_view(command["x"], command["y"])), 60)
            except (ValueError, RuntimeError, IndexError, asyncio.TimeoutError) as e:
                client.send_text({"type": "error", "message": f"map view: {e}"})
            else:
                client.send_binary(messages.encode_map(result, heat))
        elif kind == "reference":
            try:
                if command["source"] == "saved":
                    self.session.reference_from_saved()
                else:
                    self.session.set_reference(None, "")
            except ValueError as e:
                client.send_text({"type": "error", "message": f"reference: {e}"})
                return
            data = messages.encode_reference(self.session.reference_name, self.session.reference)
            for c in list(self.clients):  # every page shows the same view, and measures it the same way
                c.send_binary(data)
                c.send_text(self.session.state())
        elif kind == "save":
            try:
                files = await asyncio.get_running_loop().run_in_executor(None, self.session.save, command["exposure"])
            except (OSError, RuntimeError, ValueError) as e:
                client.send_text({"type": "error", "message": f"save: {e}"})
            else:
                client.send_text({"type": "saved", "files": files})

    async def serve(self, sock, stop: asyncio.Event) -> None:
        """Serves on the bound socket until stop is set; then ends the render and closes every page."""
        self.loop = asyncio.get_running_loop()
        self.port = sock.getsockname()[1]
        self.session.on_frame = self._frame
        self.session.on_message = self._message
        runner = web.AppRunner(self.app, handle_signals=False, access_log=None, shutdown_timeout=2.0)
        await runner.setup()
        await web.SockSite(runner, sock).start()
        self.session.start()
        try:
            await stop.wait()
        finally:
            await self.loop.run_in_executor(None, self.session.stop)
            for c in list(self.clients):
                await c.ws.close(code=1001, message=b"neepp view stopped")
            await runner.cleanup()
