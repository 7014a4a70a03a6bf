// Filters by verdict, section and text; the matrix's cells set them. A link to a case
// (the failures' list) shows it open, whatever the filters. Works offline.
(function () {
  var boxes = document.querySelectorAll('#filters input[type=checkbox]');
  var section = document.getElementById('f-section');
  var text = document.getElementById('f-text');
  function apply() {
    var shown = {};
    boxes.forEach(function (b) { shown[b.value] = b.checked; });
    var want = text.value.toLowerCase();
    document.querySelectorAll('details.case').forEach(function (d) {
      var ok = shown[d.dataset.verdict] &&
        (!section.value || d.dataset.section === section.value) &&
        (!want || d.id.toLowerCase().indexOf(want) >= 0);
      d.classList.toggle('hidden', !ok);
    });
    document.querySelectorAll('section.cases').forEach(function (s) {
      s.classList.toggle('hidden', !s.querySelector('details.case:not(.hidden)'));
    });
  }
  boxes.forEach(function (b) { b.addEventListener('change', apply); });
  section.addEventListener('change', apply);
  text.addEventListener('input', apply);
  function reveal(id) {
    var d = document.getElementById(id);
    if (!d || d.tagName !== 'DETAILS') return;
    d.open = true;
    d.classList.remove('hidden');
    var s = d.closest('section.cases');
    if (s) s.classList.remove('hidden');
  }
  document.querySelectorAll('#failed a[href^="#case-"]').forEach(function (a) {
    a.addEventListener('click', function () { reveal(a.getAttribute('href').slice(1)); });
  });
  if (location.hash) reveal(location.hash.slice(1));
  document.querySelectorAll('a[data-verdict]').forEach(function (a) {
    a.addEventListener('click', function () {
      boxes.forEach(function (b) { b.checked = !a.dataset.verdict || b.value === a.dataset.verdict; });
      section.value = a.dataset.section || '';
      apply();
    });
  });
})();
