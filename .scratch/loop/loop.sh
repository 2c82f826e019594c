set -x
export PATH=/work/wt/i23-semester/.venv/bin:/usr/bin:/bin
robot-lab course nbgrader course && cd course
nbgrader generate_assignment ex06
nbgrader release_assignment ex06
cd ..
mkdir alice bob carol
for s in alice bob carol; do (cd $s && cp ../course/students/nbgrader_config.py . && nbgrader fetch_assignment ex06); done
ls alice/ex06
cp course/source/ex06/ex06_ros_bags.ipynb alice/ex06/
python -c "import nbformat as n; nb=n.read('course/source/ex06/ex06_ros_bags.ipynb', 4); nb.cells=[c for c in nb.cells if c.metadata.get('nbgrader', {}).get('grade_id') != 'record']; n.write(nb, 'bob/ex06/ex06_ros_bags.ipynb')"
nbgrader validate alice/ex06/ex06_ros_bags.ipynb
nbgrader validate carol/ex06/ex06_ros_bags.ipynb | head -3
for s in alice bob carol; do (cd $s && nbgrader submit ex06 --student $s); done
robot-lab course nbgrader course && cd course
nbgrader collect ex06
nbgrader autograde ex06
nbgrader generate_feedback ex06
nbgrader release_feedback ex06
nbgrader export
cat grades.csv
