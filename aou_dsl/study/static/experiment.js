/* aou's perception study, run by jsPsych 8: written by `aouc study build`.
 *
 * The page reads timeline.json (blind ids, videos, texts) and draws, from a seed of the
 * participant's own, the order of the questions, the layout of Part A's videos and the
 * side of each Part B pair. Every answer row carries the fields `aouc study analyze`
 * reads (participant, aou_part, aou_item, state, other_text, description, intensity,
 * answer, left, passed, order); the last row is aou_part "end" with the whole order and
 * the sides. The rows are sent to the server that served the page (POST submit) or to
 * JATOS; while that fails they are kept in the browser, tried again, and offered as a
 * download.
 */
(function () {
  "use strict";

  var params = new URLSearchParams(window.location.search);
  var inJatos = typeof window.jatos !== "undefined";

  // A 32-bit hash of a text (FNV-1a), and a small seeded generator (mulberry32).
  function hash32(text) {
    var h = 0x811c9dc5;
    for (var i = 0; i < text.length; i++) {
      h ^= text.charCodeAt(i);
      h = Math.imul(h, 0x01000193) >>> 0;
    }
    return h >>> 0;
  }
  function generator(seed) {
    var a = seed >>> 0;
    return function () {
      a = (a + 0x6d2b79f5) >>> 0;
      var t = a;
      t = Math.imul(t ^ (t >>> 15), t | 1);
      t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
      return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
    };
  }
  function shuffled(items, random) {
    var out = items.slice();
    for (var i = out.length - 1; i > 0; i--) {
      var j = Math.floor(random() * (i + 1));
      var t = out[i]; out[i] = out[j]; out[j] = t;
    }
    return out;
  }
  function randomId() {
    var b = new Uint8Array(8);
    window.crypto.getRandomValues(b);
    return "p-" + Array.prototype.map.call(b, function (x) {
      return ("0" + x.toString(16)).slice(-2);
    }).join("");
  }
  function esc(text) {
    return String(text == null ? "" : text).replace(/[&<>"']/g, function (c) {
      return {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;"}[c];
    });
  }
  function paragraphs(text) {
    return String(text || "").split(/\n\s*\n/).map(function (p) {
      return "<p>" + esc(p) + "</p>";
    }).join("");
  }
  function video(src) {
    return '<video src="' + esc(src) + '" loop muted playsinline autoplay preload="auto"' +
      ' disablepictureinpicture></video>';
  }
  function startVideos() {
    document.querySelectorAll("video").forEach(function (v) {
      v.muted = true;
      var p = v.play();
      if (p && p.catch) p.catch(function () {});
    });
  }
  function cap(s) { return s.charAt(0).toUpperCase() + s.slice(1); }

  function run(design) {
    var platform = {
      prolific_pid: params.get("PROLIFIC_PID") || "",
      study_id: params.get("STUDY_ID") || "",
      session_id: params.get("SESSION_ID") || ""
    };
    var participant = platform.prolific_pid ||
      (inJatos && window.jatos.workerId ? "jatos-" + window.jatos.workerId : "") || randomId();
    var seed = hash32(String(design.seed) + ":" + participant);
    var random = generator(seed);
    var storeKey = "aou-study:" + participant;

    var jsPsych = initJsPsych({on_finish: finish});
    jsPsych.data.addProperties({participant: participant, aou_seed: seed,
                                PROLIFIC_PID: platform.prolific_pid,
                                STUDY_ID: platform.study_id, SESSION_ID: platform.session_id});

    var order = 0;
    var declined = false;  // no consent: nothing is recorded or sent
    var orderOf = [];
    var sides = {};
    var timeline = [];

    timeline.push({
      type: jsPsychHtmlButtonResponse,
      stimulus: "<h2>" + esc(design.title) + "</h2>" + paragraphs(design.texts.consent),
      choices: ["I agree", "I do not agree"],
      data: {aou_page: "consent"},
      on_finish: function (data) {
        if (data.response !== 0) {
          declined = true;
          jsPsych.abortExperiment("<p>You did not agree to take part. You may close this " +
                                  "page.</p>");
        }
      }
    });

    // Part A: every video on the page, in this participant's layout; one question each.
    var layout = shuffled(design.part_a, random);
    var number = {};
    layout.forEach(function (s, i) { number[s.item] = i + 1; });
    if (design.part_a.length) {
      timeline.push({type: jsPsychHtmlButtonResponse, choices: ["Continue"],
                     stimulus: paragraphs(design.texts.instructions_a),
                     data: {aou_page: "instructions_a"}});
    }
    shuffled(design.part_a, random).forEach(function (s) {
      var position = ++order;
      orderOf.push(s.item);
      var grid = '<div class="aou-videos">' + layout.map(function (o) {
        return '<figure class="' + (o.item === s.item ? "aou-asked" : "") + '">' +
          video(o.video) + "<figcaption>Video " + number[o.item] + "</figcaption></figure>";
      }).join("") + "</div>";
      var options = design.states.map(function (st) {
        return '<label><input type="radio" name="state" value="' + esc(st) + '" required> ' +
          esc(cap(st)) + "</label>";
      });
      if (design.others) {
        options.push('<label><input type="radio" name="state" value="others"> Others: ' +
                     '<input type="text" name="other_text" maxlength="500"></label>');
      }
      if (design.none) {
        options.push('<label><input type="radio" name="state" value="none"> None</label>');
      }
      var scale = [];
      for (var k = 1; k <= design.intensity; k++) {
        scale.push('<label style="display:inline-block;margin-right:12px"><input ' +
                   'type="radio" name="intensity" value="' + k + '" required> ' + k +
                   "</label>");
      }
      timeline.push({
        type: jsPsychSurveyHtmlForm,
        preamble: grid,
        html: '<div class="aou-form"><p><b>Video ' + number[s.item] + "</b> (outlined): " +
          "describe in your own words how the robot behaves.</p>" +
          '<textarea name="description" rows="3" maxlength="2000" required></textarea>' +
          "<p>Which state describes it best?</p>" + options.join("") +
          "<p>How strongly does it show it? (1: weakly, " + design.intensity +
          ": strongly)</p>" + scale.join("") + "</div>",
        button_label: "Next",
        on_load: startVideos,
        data: {aou_part: "A", aou_item: s.item, order: position},
        on_finish: function (data) {
          var r = data.response || {};
          data.state = r.state;
          data.other_text = r.state === "others" ? (r.other_text || "") : "";
          data.description = r.description || "";
          data.intensity = r.intensity ? parseInt(r.intensity, 10) : null;
        }
      });
    });

    // Part B: the pairs and the attention checks, in this participant's order.
    var questions = design.part_b.map(function (p) { return {pair: p}; })
      .concat((design.attention || []).map(function (c) { return {check: c}; }));
    if (design.part_b.length) {
      timeline.push({type: jsPsychHtmlButtonResponse, choices: ["Continue"],
                     stimulus: paragraphs(design.texts.instructions_b),
                     data: {aou_page: "instructions_b"}});
    }
    shuffled(questions, random).forEach(function (q) {
      var position = ++order;
      if (q.check) {
        var c = q.check;
        orderOf.push(c.item);
        timeline.push({
          type: jsPsychHtmlButtonResponse, stimulus: "<p>" + esc(c.question) + "</p>",
          choices: c.options, data: {aou_part: "attention", aou_item: c.item, order: position},
          on_finish: function (data) { data.passed = c.options[data.response] === c.answer; }
        });
        return;
      }
      var p = q.pair;
      orderOf.push(p.item);
      // The pair's videos in file order; the parity of k says whether the first is low.
      var low = p.k % 2 === 0 ? p.videos[0] : p.videos[1];
      var high = p.k % 2 === 0 ? p.videos[1] : p.videos[0];
      var left = random() < 0.5 ? "low" : "high";
      sides[p.item] = left;
      var shown = left === "low" ? [low, high] : [high, low];
      var asked = p.state ? "more <b>" + esc(p.state) + "</b>" : "the robot's state more strongly";
      timeline.push({
        type: jsPsychHtmlButtonResponse,
        stimulus: '<div class="aou-videos"><figure>' + video(shown[0]) +
          "<figcaption>Left</figcaption></figure><figure>" + video(shown[1]) +
          "<figcaption>Right</figcaption></figure></div><p>Which video looks " + asked + "?</p>",
        choices: ["Left", "Right", "Both equally", "Neither"],
        on_load: startVideos,
        data: {aou_part: "B", aou_item: p.item, order: position, left: left},
        on_finish: function (data) {
          var right = left === "low" ? "high" : "low";
          data.answer = [left, right, "both", "neither"][data.response];
        }
      });
    });

    if (design.demographics.length) {
      timeline.push({
        type: jsPsychSurveyHtmlForm,
        preamble: "<p>A few questions about you (each may be left empty).</p>",
        html: '<div class="aou-form">' + design.demographics.map(function (d, i) {
          return "<label>" + esc(d) + ' <input type="text" name="d' + i +
            '" maxlength="200"></label>';
        }).join("") + "</div>",
        button_label: "Next",
        data: {aou_page: "demographics"},
        on_finish: function (data) {
          var r = data.response || {};
          var out = {};
          design.demographics.forEach(function (d, i) { out[d] = r["d" + i] || ""; });
          data.aou_demographics = out;
        }
      });
    }

    function finish() {
      if (declined) return;
      var rows = jsPsych.data.get().values();
      rows.push({participant: participant, aou_part: "end", aou_item: "", aou_seed: seed,
                 aou_order: orderOf, aou_sides: sides, PROLIFIC_PID: platform.prolific_pid,
                 STUDY_ID: platform.study_id, SESSION_ID: platform.session_id});
      send(rows);
    }

    function endPage(status) {
      var code = design.completion && design.completion.code;
      var el = jsPsych.getDisplayElement();
      el.innerHTML = '<div id="aou-end">' + paragraphs(design.texts.end || "Thank you.") +
        (code ? '<p>Your completion code: <b id="aou-code">' + esc(code) + "</b></p>" : "") +
        '<p id="aou-status">' + status + "</p></div>";
    }

    function send(rows) {
      var text = JSON.stringify(rows);
      try { window.localStorage.setItem(storeKey, text); } catch (e) { /* full or off */ }
      endPage("Sending your answers…");
      if (inJatos) {
        var redirect = design.completion && design.completion.redirect;
        if (redirect) window.jatos.endStudyAndRedirect(redirect, text);
        else window.jatos.endStudy(text);
        return;
      }
      var offered = false;
      function sent(how) {
        try { window.localStorage.removeItem(storeKey); } catch (e) { /* off */ }
        document.getElementById("aou-status").textContent = how;
        var redirect = design.completion && design.completion.redirect;
        if (redirect) window.location.href = redirect;
      }
      function offer() {
        if (offered) return;
        offered = true;
        var url = URL.createObjectURL(new Blob([text], {type: "application/json"}));
        var p = document.createElement("p");
        p.id = "aou-offline";
        p.innerHTML = "The study's server cannot be reached. Your answers are kept in " +
          "this browser and sent as soon as it answers; you can also " +
          '<a id="aou-download" download="answers-' + esc(participant) + '.json" href="' +
          url + '">download them</a> and send the file to the researcher.';
        document.getElementById("aou-end").appendChild(p);
      }
      function attempt() {
        fetch("submit", {method: "POST", headers: {"Content-Type": "application/json"},
                         body: JSON.stringify({participant: participant, data: rows})})
          .then(function (r) {
            if (r.status === 201) sent("Your answers were received.");
            else if (r.status === 409) sent("Your answers had already been received.");
            else throw new Error("status " + r.status);
          })
          .catch(function () { offer(); window.setTimeout(attempt, 1500); });
      }
      attempt();
    }

    jsPsych.run(timeline);
  }

  function start() {
    fetch("timeline.json").then(function (r) { return r.json(); }).then(run)
      .catch(function (e) {
        document.body.innerHTML = "<p>The study could not be loaded: " + esc(e) + "</p>";
      });
  }
  if (inJatos) window.jatos.onLoad(start);
  else if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start);
  else start();
})();
