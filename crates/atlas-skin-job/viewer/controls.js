// The side panel's controls: the joint list with its rotation sliders, the view options and
// the animation player.

const AXES = ['x', 'y', 'z'];

// Makes skin joint j the selected one: in the joint list, on the sliders (its user rotation)
// and in the view (highlighted point, heat map).
function selectJoint(viewer, j) {
  viewer.state.joint = j;
  $('joint').value = String(j);
  const user = viewer.scene.nodes[viewer.mainSkin.joints[j]].user;
  AXES.forEach((a, k) => {
    $(`rot-${a}`).value = String(user[k]);
    $(`rot-${a}-value`).textContent = `${Math.round(user[k])}°`;
  });
  requestRender(viewer);
}

// The joint list, the X/Y/Z sliders turning the selected joint (degrees) and the pose reset.
function bindJointControls(viewer) {
  const { scene, mainSkin, state } = viewer;
  const jointSelect = $('joint');
  viewer.jointNames.forEach((name, j) => jointSelect.appendChild(element('option', name)).setAttribute('value', String(j)));
  jointSelect.addEventListener('change', () => selectJoint(viewer, Number(jointSelect.value)));
  AXES.forEach((a, k) => $(`rot-${a}`).addEventListener('input', (event) => {
    const degrees = Number(event.target.value);
    scene.nodes[mainSkin.joints[state.joint]].user[k] = degrees;
    $(`rot-${a}-value`).textContent = `${degrees}°`;
    requestRender(viewer);
  }));
  $('reset-pose').addEventListener('click', () => {
    scene.nodes.forEach((node) => (node.user = [0, 0, 0]));
    selectJoint(viewer, state.joint);
  });
}

// Regions, one joint's weights or piece treatments (offered when the report has them, with
// their legend while shown), LBS or DQS, and whether the skeleton and boundaries show.
function bindViewOptions(viewer) {
  const { state } = viewer;
  const modes = [
    ['colour-regions', { heat: false, pieces: false }],
    ['colour-weights', { heat: true, pieces: false }],
    ['colour-pieces', { heat: false, pieces: true }],
    ['method-lbs', { dqs: false }],
    ['method-dqs', { dqs: true }],
  ];
  for (const [id, values] of modes) {
    $(id).addEventListener('change', () => {
      Object.assign(state, values);
      $('pieces-legend').hidden = !state.pieces;
      requestRender(viewer);
    });
  }
  if (viewer.colours.pieces) {
    $('pieces-option').hidden = false;
    renderPieceLegend(viewer.treatmentNames, viewer.treatmentCounts);
  }
  for (const key of ['skeleton', 'curves']) {
    $(`show-${key}`).addEventListener('change', (event) => {
      state[key] = event.target.checked;
      requestRender(viewer);
    });
  }
}

// The animation list, Play/Pause (playing the first animation when none is chosen) and the
// time slider (a fraction of the duration).
function bindAnimationControls(viewer) {
  const { animations, state } = viewer;
  const animSelect = $('animation');
  animations.forEach((a, i) => animSelect.appendChild(element('option', `${a.name} (${a.duration.toFixed(2)} s)`)).setAttribute('value', String(i)));
  animSelect.addEventListener('change', () => {
    state.animation = Number(animSelect.value);
    state.time = 0;
    $('time').value = '0';
    requestRender(viewer);
  });
  $('play').disabled = !animations.length;
  $('play').addEventListener('click', () => {
    if (state.animation < 0 && animations.length) {
      state.animation = 0;
      animSelect.value = '0';
    }
    state.playing = !state.playing && state.animation >= 0;
    viewer.playback.lastFrame = 0;
    $('play').textContent = state.playing ? 'Pause' : 'Play';
    requestRender(viewer);
  });
  $('time').addEventListener('input', (event) => {
    const animation = animations[state.animation];
    state.time = animation ? Number(event.target.value) * animation.duration : 0;
    requestRender(viewer);
  });
}
