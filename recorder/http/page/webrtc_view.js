// The live picture over WebRTC (WHEP: the offer POSTed, the answer back),
// VP8 at a third of MJPEG's bitrate; MJPEG when the browser has no WebRTC,
// the recorder has it off, or the connection does not come up. The card's
// head says which one shows. The peer connection also carries the drive
// mode's data channel (control.js), unordered and never retransmitted: a
// lost command is replaced by the next one, never delivered late.
const kWebRtcPatienceMs = 5000;  // to connect, before MJPEG takes over

function showTransport(view, transport) {
  view.box.dataset.transport = transport;
  view.transport.textContent = transport === "webrtc" ? "WebRTC" : "MJPEG";
  view.img.hidden = transport === "webrtc";
  view.video.hidden = transport !== "webrtc";
}

function showMjpeg(view, name) {
  showTransport(view, "mjpeg");
  view.img.src = "/live/" + encodeURIComponent(name) + ".mjpg?t=" + Date.now();
}

// Starts the picture of a camera that went live: WebRTC first.
async function startPicture(view, name) {
  stopPicture(view);
  const attempt = view.attempt = {};
  const webrtc = window.RTCPeerConnection ? await connectWebRtc(view, name) : null;
  if (view.attempt !== attempt) {  // stopped or restarted meanwhile
    if (webrtc) closeWebRtc(webrtc);
    return;
  }
  if (!webrtc) return showMjpeg(view, name);
  view.webrtc = webrtc;
  showTransport(view, "webrtc");
}

function stopPicture(view) {
  view.attempt = null;
  if (view.webrtc) closeWebRtc(view.webrtc);
  view.webrtc = null;
  view.img.removeAttribute("src");
  view.video.srcObject = null;
}

// A peer connection showing `name` in the card's video, or null.
async function connectWebRtc(view, name) {
  // No ICE servers: the recorder's answer carries its candidates, and no
  // third party is asked anything.
  const pc = new RTCPeerConnection();
  const webrtc = { pc, session: null, drive: null };
  try {
    pc.addTransceiver("video", { direction: "recvonly" });
    if (view.controls)
      webrtc.drive = pc.createDataChannel("drive", { ordered: false, maxRetransmits: 0 });
    pc.ontrack = event => { view.video.srcObject = new MediaStream([event.track]); };
    await pc.setLocalDescription(await pc.createOffer());
    await gathered(pc);
    const response = await fetch(`/api/cameras/${encodeURIComponent(name)}/whep`, {
      method: "POST", headers: { "Content-Type": "application/sdp" },
      body: pc.localDescription.sdp });
    if (response.status !== 201) throw new Error(`WHEP ${response.status}`);
    webrtc.session = response.headers.get("Location");
    await pc.setRemoteDescription({ type: "answer", sdp: await response.text() });
    await connected(pc);
    pc.addEventListener("connectionstatechange", () => {
      if (pc.connectionState !== "failed" || view.webrtc !== webrtc) return;
      // Lost on the way (a network change): MJPEG until the state changes.
      closeWebRtc(webrtc);
      view.webrtc = null;
      showMjpeg(view, name);
    });
    return webrtc;
  } catch (error) {
    console.log(`WebRTC for ${name}: ${error.message}; showing MJPEG`);
    closeWebRtc(webrtc);
    return null;
  }
}

function gathered(pc) {
  return new Promise(done => {
    if (pc.iceGatheringState === "complete") return done();
    pc.addEventListener("icegatheringstatechange", () => {
      if (pc.iceGatheringState === "complete") done();
    });
    setTimeout(done, 2000);  // what is there by then
  });
}

function connected(pc) {
  return new Promise((done, fail) => {
    const timer = setTimeout(() => fail(new Error("no connection")), kWebRtcPatienceMs);
    const check = () => {
      if (pc.connectionState === "connected") { clearTimeout(timer); done(); }
      if (pc.connectionState === "failed") { clearTimeout(timer); fail(new Error("failed")); }
    };
    pc.addEventListener("connectionstatechange", check);
    check();
  });
}

// The session ends on the recorder too (WHEP's DELETE), even as the page
// is unloading.
function closeWebRtc(webrtc) {
  webrtc.pc.close();
  if (webrtc.session) fetch(webrtc.session, { method: "DELETE", keepalive: true });
  webrtc.session = null;
}

window.addEventListener("pagehide", () => {
  for (const view of Object.values(views)) if (view.webrtc) closeWebRtc(view.webrtc);
});
